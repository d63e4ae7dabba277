#pragma once
/// Reading fields of the project's own JSON files with errors that name the file and the JSON
/// path (private to vessel::reports: it includes nlohmann/json).
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "meshes/foundation/errors.hpp"

namespace vessel::reports::json_fields {

using nlohmann::json;

/// j[key] as T, or an InputError naming `where` (file and JSON path) and the key.
template <class T>
T field(const json& j, const char* key, const std::string& where) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) {
    throw InputError(where + ": missing field '" + key + "'");
  }
  try {
    return it->get<T>();
  } catch (const json::exception&) {
    throw InputError(where + ": field '" + key + "' has the wrong type (" + it->type_name() + ")");
  }
}

/// j[key] as T, or `fallback` where it is absent or null.
template <class T>
T field_or(const json& j, const char* key, T fallback, const std::string& where) {
  const auto it = j.find(key);
  return it == j.end() || it->is_null() ? fallback : field<T>(j, key, where);
}

/// j[key] as T, or nullopt where it is absent or null.
template <class T>
std::optional<T> optional_field(const json& j, const char* key, const std::string& where) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::nullopt;
  return field<T>(j, key, where);
}

/// The text as a JSON object whose "schema" is `schema` and "schema_version" is `version`;
/// InputError naming `file` and what was expected otherwise. `what` names such a file ("results
/// file") and `producer` the command that writes it, for the messages.
inline json parse_versioned(const std::string& text, const std::string& file, const char* schema,
                            int version, const std::string& what, const std::string& producer) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(file + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("schema") || !j["schema"].is_string() ||
      j["schema"].get<std::string>() != schema) {
    throw InputError(file + ": not a vesselverify " + what + " (expected \"schema\": \"" +
                     schema + "\", as `" + producer + "` writes)");
  }
  const int found = field<int>(j, "schema_version", file);
  if (found != version) {
    throw InputError(file + ": schema_version " + std::to_string(found) + ", expected " +
                     std::to_string(version) + " (rerun `" + producer + "` with this build)");
  }
  return j;
}

/// A file's whole text; InputError naming it if it cannot be opened.
inline std::string read_text(const std::filesystem::path& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open " + what);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace vessel::reports::json_fields
