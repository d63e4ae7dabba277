// The scene table (verification/scene_keys.hpp): the parser reads and checks every key it lists,
// its names agree with the msm parsers', and its JSON Schema accepts the shipped scenes and
// refuses what the parser refuses.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <toml++/toml.h>

#include "meshes/foundation/errors.hpp"
#include "msm/mass/mass_rules.hpp"
#include "msm/model/build_network.hpp"
#include "msm/solvers/solve.hpp"
#include "msm/stiffness/stiffness_rules.hpp"
#include "verification/scene.hpp"
#include "verification/scene_keys.hpp"
#include "test_paths.hpp"

using namespace vessel;
using Json = nlohmann::json;

namespace {

/// A valid scene whose `section` is in `variant`, as (header, key → TOML value) blocks.
using Blocks = std::vector<std::pair<std::string, std::map<std::string, std::string>>>;

Blocks base_scene(const std::string& section, const std::string& variant) {
  std::map<std::string, std::string> vessel{{"kind", "\"straight\""}, {"level", "0"}};
  if (section == "vessel" && variant == "file") vessel = {{"file", "\"none.msh\""}};
  if (section == "vessel" && variant == "lumen") {
    vessel = {{"lumen", "\"none.stl\""}, {"wall_thickness", "1e-3"}};
  }
  std::map<std::string, std::string> load{
      {"type", "\"contact\""}, {"magnitudes", "[0.01]"}, {"point", "[3e-3, 0, 20e-3]"}};
  if (section == "load" && variant != "contact") {
    load = {{"type", "\"" + variant + "\""}, {"magnitudes", "[1.0]"}};
  }
  if (section == "load" && variant == "guidewire") {  // EI = 4e-7 N·m², touching at z ≈ 20 mm
    load = {{"type", "\"guidewire\""}, {"E", "5.073e8"}, {"diameter", "0.356e-3"},
            {"insertion", "20.25e-3"}, {"coupling", "\"compliant\""}};
  }
  std::map<std::string, std::string> model{{"kind", "\"fem\""}};
  if (section == "models") model = {{"kind", "\"" + variant + "\""}};
  if (section == "models" && variant == "network") model["file"] = "\"x.json\"";
  if (section == "models" && variant == "displacements") model["file"] = "\"answers\"";
  if (section == "models" && variant == "external") model["command"] = "[\"true\"]";
  return {{"", {{"name", "\"t\""}}}, {"[vessel]", vessel}, {"[load]", load},
          {"[[models]]", model}, {"[budget]", {{"rate_hz", "30"}}}, {"[material]", {}},
          {"[boundary]", {}}, {"[tolerances]", {}}, {"[modes]", {}}, {"[transient]", {}}};
}

std::string text_of(const Blocks& blocks) {
  std::string text;
  for (const auto& [header, keys] : blocks) {
    text += header.empty() ? "" : header + "\n";
    for (const auto& [k, v] : keys) text += k + " = " + v + "\n";
  }
  return text;
}

std::string error_of(const std::string& text) {
  try {
    (void)parse_scene(text, "scene.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// The variants of a section ({""} for one without).
std::vector<std::string> variants_of(const std::string& section) {
  for (const auto& s : scene_sections()) {
    if (s.name == section) return s.variants.empty() ? std::vector<std::string>{""} : s.variants;
  }
  return {};
}

/// Checks `value` against the JSON Schema keywords scene_json_schema() uses; "" if it holds,
/// else where it fails.
std::string violation(const Json& schema, const Json& value, const std::string& at) {
  const auto fail = [&](const std::string& what) { return at + ": " + what; };
  if (schema.contains("type")) {
    const std::string t = schema["type"];
    const bool ok = (t == "object" && value.is_object()) || (t == "array" && value.is_array()) ||
                    (t == "string" && value.is_string()) || (t == "boolean" && value.is_boolean()) ||
                    (t == "integer" && value.is_number_integer()) ||
                    (t == "number" && value.is_number());
    if (!ok) return fail("not " + t);
  }
  if (schema.contains("enum") &&
      std::find(schema["enum"].begin(), schema["enum"].end(), value) == schema["enum"].end()) {
    return fail("not in enum");
  }
  if (schema.contains("const") && schema["const"] != value) return fail("not the const");
  if (value.is_number()) {
    const double v = value.get<double>();
    if (schema.contains("minimum") && v < schema["minimum"].get<double>()) return fail("< minimum");
    if (schema.contains("maximum") && v > schema["maximum"].get<double>()) return fail("> maximum");
    if (schema.contains("exclusiveMinimum") && v <= schema["exclusiveMinimum"].get<double>()) {
      return fail("<= exclusiveMinimum");
    }
  }
  if (value.is_array()) {
    if (schema.contains("minItems") && value.size() < schema["minItems"]) return fail("too few");
    if (schema.contains("maxItems") && value.size() > schema["maxItems"]) return fail("too many");
    for (std::size_t i = 0; schema.contains("items") && i < value.size(); ++i) {
      if (auto v = violation(schema["items"], value[i], at + "[" + std::to_string(i) + "]"); !v.empty()) return v;
    }
  }
  if (value.is_string() && schema.contains("minLength") &&
      value.get<std::string>().size() < schema["minLength"].get<std::size_t>()) {
    return fail("too short");
  }
  if (value.is_object()) {
    for (const auto& r : schema.value("required", Json::array())) {
      if (!value.contains(r.get<std::string>())) return fail("missing " + r.get<std::string>());
    }
    for (const auto& [k, v] : value.items()) {
      if (schema.contains("properties") && schema["properties"].contains(k)) {
        if (auto e = violation(schema["properties"][k], v, at + "." + k); !e.empty()) return e;
      } else if (schema.value("additionalProperties", true) == false) {
        return fail("unknown " + k);
      }
      if (schema.contains("propertyNames") &&
          violation(schema["propertyNames"], Json(k), at).size() > 0) {
        return fail("unknown " + k);
      }
    }
  }
  for (const auto& clause : schema.value("allOf", Json::array())) {
    if (violation(clause["if"], value, at).empty()) {
      if (auto e = violation(clause["then"], value, at); !e.empty()) return e;
    }
  }
  if (schema.contains("not") && violation(schema["not"], value, at).empty()) return fail("not");
  if (schema.contains("anyOf")) {
    bool any = false;
    for (const auto& s : schema["anyOf"]) any = any || violation(s, value, at).empty();
    if (!any) return fail("no anyOf matches");
  }
  return "";
}

Json scene_as_json(const std::string& text) {
  std::ostringstream s;
  s << toml::json_formatter{toml::parse(text)};
  return Json::parse(s.str());
}

}  // namespace

// Every key of the table, given a value of the wrong type (an inline table) in a scene that is
// otherwise valid, is refused naming that key: the parser reads every key the table lists (a key
// it ignored would pass). Keys that only some settings allow (dt with a static solver) are
// refused for that, also naming the key.
TEST(SceneKeys, EveryKeyIsReadAndItsTypeChecked) {
  int checked = 0;
  for (const SceneKey& k : scene_keys()) {
    if (k.type == KeyType::table || k.type == KeyType::tables) continue;
    for (const std::string& variant : variants_of(k.section)) {
      if (!k.applies_to(variant)) continue;
      Blocks blocks = base_scene(k.section, variant);
      const std::string header = k.section.empty() ? ""
                                 : k.section == "models" ? "[[models]]"
                                                         : "[" + k.section + "]";
      for (auto& [h, keys] : blocks) {
        if (h == header) keys[k.name] = "{ x = 1 }";
      }
      const std::string prefix = k.section.empty() ? "" : k.section == "models" ? "models[0]." : k.section + ".";
      const std::string e = error_of(text_of(blocks));
      EXPECT_NE(e.find("key '" + prefix + k.name + "'"), std::string::npos)
          << k.section << "." << k.name << " (" << variant << "): " << e;
      EXPECT_NE(e.find("found"), std::string::npos) << e;
      ++checked;
    }
  }
  EXPECT_GE(checked, 80);
}

// A key of another variant is unknown, and the message lists the variant's keys.
TEST(SceneKeys, AKeyOfAnotherVariantIsUnknown) {
  Blocks blocks = base_scene("models", "fem");
  blocks[3].second["stiffness"] = "\"lloyd\"";
  const std::string e = error_of(text_of(blocks));
  EXPECT_NE(e.find("key 'models[0].stiffness': unknown key; expected one of: kind, name, degree"),
            std::string::npos) << e;
  blocks = base_scene("models", "volume_msm");
  blocks[3].second["dt"] = "1e-4";
  EXPECT_NE(error_of(text_of(blocks)).find("key 'models[0].dt': found with solver \"static\""),
            std::string::npos);
}

// The table's names are the msm parsers': each accepted by them, and every value of each enum
// listed (by its to_string name).
TEST(SceneKeys, ChoicesAreTheNamesTheMsmParsersRead) {
  const auto choices = [](const std::string& key, const std::string& variant) {
    return find_scene_key("models", key, variant)->choices;
  };
  const auto listed = [](const std::vector<std::string>& c, const std::string& name) {
    return std::find(c.begin(), c.end(), name) != c.end();
  };
  for (const auto& n : choices("stiffness", "volume_msm")) EXPECT_NO_THROW(msm::parse_stiffness_rule(n)) << n;
  for (const auto r : {msm::StiffnessRule::seed000, msm::StiffnessRule::seed001,
                       msm::StiffnessRule::van_gelder, msm::StiffnessRule::lloyd,
                       msm::StiffnessRule::least_squares_fit, msm::StiffnessRule::uniform}) {
    EXPECT_TRUE(listed(choices("stiffness", "volume_msm"), msm::to_string(r))) << msm::to_string(r);
  }
  for (const auto& n : choices("mass", "volume_msm")) EXPECT_NO_THROW(msm::parse_mass_rule(n)) << n;
  for (const auto r : {msm::MassRule::uniform, msm::MassRule::seed001, msm::MassRule::consistent}) {
    EXPECT_TRUE(listed(choices("mass", "volume_msm"), msm::to_string(r)));
  }
  for (const char* n : msm::kSolverNames) EXPECT_TRUE(listed(choices("solver", "network"), n)) << n;
  for (const auto& n : choices("topology", "surface_msm")) EXPECT_NO_THROW(msm::parse_topology(n));
  for (const auto& n : choices("bending", "surface_msm")) EXPECT_NO_THROW(msm::parse_bending(n));
  for (const auto& n : choices("volume_moduli", "volume_msm")) EXPECT_NO_THROW(msm::parse_volume_moduli(n));
  for (const auto& n : choices("surface", "surface_msm")) EXPECT_NO_THROW(msm::parse_wall_surface(n));
  EXPECT_EQ(choices("surface", "surface_msm").size(), 3u);
  // Defaults the parser takes from msm agree with the table's.
  EXPECT_EQ(find_scene_key("models", "iterations", "volume_msm")->default_value,
            std::to_string(msm::SolverSpec{}.local_global.iterations));
  EXPECT_EQ(find_scene_key("models", "surface", "surface_msm")->default_value,
            "\"" + msm::to_string(msm::NetworkOptions{}.surface) + "\"");
}

// The JSON Schema accepts every shipped scene and refuses what the parser refuses.
TEST(SceneKeys, JsonSchemaAcceptsTheShippedScenesAndRefusesBadOnes) {
  const Json schema = Json::parse(scene_json_schema());
  EXPECT_EQ(schema["$schema"], "https://json-schema.org/draft/2020-12/schema");
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(VESSEL_SCENES_DIR)) {
    if (entry.path().extension() != ".toml") continue;
    std::ifstream in(entry.path());
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(violation(schema, scene_as_json(text.str()), "scene"), "") << entry.path();
    ++scenes;
  }
  EXPECT_GE(scenes, 5);
  const std::string good = text_of(base_scene("models", "volume_msm"));
  EXPECT_EQ(violation(schema, scene_as_json(good), "scene"), "");
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"nu", "0.6"}, {"E", "0"}, {"colour", "1"}, {"density", "\"heavy\""}}) {
    Blocks bad = base_scene("models", "volume_msm");
    bad[5].second[key] = value;  // [material]
    EXPECT_NE(error_of(text_of(bad)), "") << key;
    EXPECT_NE(violation(schema, scene_as_json(text_of(bad)), "scene"), "") << key;
  }
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"stiffness", "\"magic\""}, {"degree", "1"}, {"solver", "[]"}, {"damping", "-1"}}) {
    Blocks bad = base_scene("models", "volume_msm");
    bad[3].second[key] = value;
    EXPECT_NE(error_of(text_of(bad)), "") << key;
    EXPECT_NE(violation(schema, scene_as_json(text_of(bad)), "scene"), "") << key;
  }
}
