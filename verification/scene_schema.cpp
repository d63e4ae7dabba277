// The scene table (scene_keys.hpp) written as a JSON Schema.
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "verification/scene_keys.hpp"

namespace vessel {

namespace {

using Json = nlohmann::ordered_json;

const SceneSection& section_named(const std::string& name) {
  for (const auto& s : scene_sections()) {
    if (s.name == name) return s;
  }
  throw std::logic_error("scene table: no section '" + name + "'");
}

Json section_schema(const SceneSection& section);

/// One value of the key (not a sweep's array).
Json value_schema(const SceneKey& k) {
  Json j;
  switch (k.type) {
    case KeyType::string:
      j["type"] = "string";
      if (!k.choices.empty()) j["enum"] = k.choices;
      break;
    case KeyType::boolean:
      j["type"] = "boolean";
      break;
    case KeyType::integer:
    case KeyType::number:
      j["type"] = k.type == KeyType::integer ? "integer" : "number";
      if (std::isfinite(k.min)) j[k.min_exclusive ? "exclusiveMinimum" : "minimum"] = k.min;
      if (std::isfinite(k.max)) j["maximum"] = k.max;
      break;
    case KeyType::vector3:
      j = {{"type", "array"}, {"items", {{"type", "number"}}}, {"minItems", 3}, {"maxItems", 3}};
      break;
    case KeyType::vectors3:
      j = {{"type", "array"},
           {"items",
            {{"type", "array"}, {"items", {{"type", "number"}}}, {"minItems", 3}, {"maxItems", 3}}},
           {"minItems", 1}};
      break;
    case KeyType::strings:
      j = {{"type", "array"}, {"items", {{"type", "string"}, {"minLength", 1}}}, {"minItems", 1}};
      break;
    case KeyType::table:
      return section_schema(section_named(k.name));
    case KeyType::tables:
      return {{"type", "array"}, {"items", section_schema(section_named(k.name))}, {"minItems", 1}};
  }
  return j;
}

Json key_schema(const SceneKey& k) {
  Json j;
  j["description"] = k.doc;
  const Json value = value_schema(k);
  if (k.sweep) {
    j["anyOf"] = Json::array({value, {{"type", "array"}, {"items", value}, {"minItems", 1}}});
  } else {
    for (const auto& [name, v] : value.items()) j[name] = v;  // a section's doc replaces k.doc
  }
  if (!k.default_value.empty()) j["default"] = Json::parse(k.default_value);
  if (!k.default_note.empty()) j["x-default"] = k.default_note;
  if (!k.unit.empty()) j["x-unit"] = k.unit;
  if (k.type != KeyType::table && k.type != KeyType::tables) j["x-expected"] = k.expected();
  return j;
}

/// The keys of `section` that apply to `variant` ("": to every variant).
std::vector<const SceneKey*> keys_of(const SceneSection& section, const std::string& variant) {
  std::vector<const SceneKey*> out;
  for (const SceneKey& k : scene_keys()) {
    if (k.section != section.name) continue;
    if (variant.empty() ? k.variants.empty() : !k.variants.empty() && k.applies_to(variant)) {
      out.push_back(&k);
    }
  }
  return out;
}

void add_keys(Json& object, const std::vector<const SceneKey*>& keys) {
  Json required = Json::array();
  for (const SceneKey* k : keys) {
    object["properties"][k->name] = key_schema(*k);
    if (k->required) required.push_back(k->name);
  }
  if (!required.empty()) object["required"] = required;
}

/// The JSON Schema `if` that picks `variant`: the selector's value, or the variant key's
/// presence (the default variant: none of them present).
Json variant_condition(const SceneSection& s, const std::string& variant) {
  if (!s.selector.empty()) {
    return {{"properties", {{s.selector, {{"const", variant}}}}}, {"required", {s.selector}}};
  }
  if (variant != s.default_variant) return {{"required", {variant}}};
  Json present = Json::array();
  for (const auto& v : s.variants) {
    if (v != s.default_variant) present.push_back({{"required", {v}}});
  }
  return {{"not", {{"anyOf", present}}}};
}

Json section_schema(const SceneSection& s) {
  Json j;
  j["type"] = "object";
  if (!s.doc.empty()) j["description"] = s.doc;
  j["properties"] = Json::object();
  add_keys(j, keys_of(s, ""));
  if (s.variants.empty()) {
    j["additionalProperties"] = false;
    return j;
  }
  // Keys of some variants only: each variant's clause lists its keys and allows no others.
  Json clauses = Json::array();
  for (const auto& variant : s.variants) {
    Json then;
    then["properties"] = Json::object();
    add_keys(then, keys_of(s, variant));
    then["propertyNames"] = {{"enum", scene_key_names(s.name, variant)}};
    clauses.push_back(
        {{"if", variant_condition(s, variant)}, {"then", then}, {"x-variant", variant}});
  }
  j["allOf"] = clauses;
  return j;
}

}  // namespace

std::string scene_json_schema() {
  Json j;
  j["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  j["title"] = "vesselverify scene";
  const Json top = section_schema(section_named(""));
  for (const auto& [name, v] : top.items()) j[name] = v;
  j["description"] =
      "A verification scene (TOML; this schema applies to it read as JSON). SI units unless a "
      "key says otherwise; relative paths are against the scene file's folder.";
  return j.dump(2) + "\n";
}

}  // namespace vessel
