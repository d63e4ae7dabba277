#pragma once
// A document checked against the subset of JSON Schema (2020-12) the project's schemas use:
// type (one or a list), const, enum, required, properties, items, minItems/maxItems, minimum and
// "$ref": "#/$defs/<name>". Keys a schema does not describe are allowed, as in JSON Schema.
// Returns one line per problem, naming the JSON path; empty when the document conforms.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace vessel::test {

namespace schema_detail {

inline bool has_type(const nlohmann::json& v, const std::string& t) {
  if (t == "object") return v.is_object();
  if (t == "array") return v.is_array();
  if (t == "string") return v.is_string();
  if (t == "boolean") return v.is_boolean();
  if (t == "null") return v.is_null();
  if (t == "integer") return v.is_number_integer();
  if (t == "number") return v.is_number();
  return false;
}

inline void check(const nlohmann::json& v, const nlohmann::json& s, const nlohmann::json& root,
                  const std::string& path, std::vector<std::string>& problems) {
  if (const auto r = s.find("$ref"); r != s.end()) {
    const std::string ref = *r;
    const std::string prefix = "#/$defs/";
    if (ref.rfind(prefix, 0) != 0 || !root.contains("$defs") ||
        !root["$defs"].contains(ref.substr(prefix.size()))) {
      problems.push_back(path + ": unresolved $ref " + ref);
      return;
    }
    check(v, root["$defs"][ref.substr(prefix.size())], root, path, problems);
  }
  if (const auto t = s.find("type"); t != s.end()) {
    bool ok = false;
    if (t->is_array()) {
      for (const auto& one : *t) ok = ok || has_type(v, one);
    } else {
      ok = has_type(v, *t);
    }
    if (!ok) problems.push_back(path + ": is " + v.type_name() + ", expected " + t->dump());
  }
  if (const auto c = s.find("const"); c != s.end() && v != *c)
    problems.push_back(path + ": is " + v.dump() + ", expected " + c->dump());
  if (const auto e = s.find("enum"); e != s.end()) {
    bool found = false;
    for (const auto& one : *e) found = found || v == one;
    if (!found) problems.push_back(path + ": " + v.dump() + " is not one of " + e->dump());
  }
  if (const auto m = s.find("minimum"); m != s.end() && v.is_number() && v < *m)
    problems.push_back(path + ": " + v.dump() + " < minimum " + m->dump());
  if (v.is_object()) {
    for (const auto& key : s.value("required", nlohmann::json::array())) {
      if (!v.contains(key)) problems.push_back(path + ": missing required '" + key.get<std::string>() + "'");
    }
    const nlohmann::json properties = s.value("properties", nlohmann::json::object());
    for (const auto& [key, sub] : properties.items()) {
      if (v.contains(key)) check(v[key], sub, root, path + "." + key, problems);
    }
  }
  if (v.is_array()) {
    if (s.contains("minItems") && v.size() < s["minItems"].get<std::size_t>())
      problems.push_back(path + ": fewer than " + s["minItems"].dump() + " items");
    if (s.contains("maxItems") && v.size() > s["maxItems"].get<std::size_t>())
      problems.push_back(path + ": more than " + s["maxItems"].dump() + " items");
    if (const auto items = s.find("items"); items != s.end()) {
      for (std::size_t i = 0; i < v.size(); ++i)
        check(v[i], *items, root, path + "[" + std::to_string(i) + "]", problems);
    }
  }
}

}  // namespace schema_detail

inline std::vector<std::string> schema_problems(const nlohmann::json& document,
                                                const nlohmann::json& schema) {
  std::vector<std::string> problems;
  schema_detail::check(document, schema, schema, "$", problems);
  return problems;
}

/// The problems as one message for a test's failure output.
inline std::string joined(const std::vector<std::string>& problems) {
  std::string out;
  for (const auto& p : problems) out += p + "\n";
  return out;
}

}  // namespace vessel::test
