#pragma once
/// The scene file described once: every key of every section, its type, default, unit, range and
/// meaning, as data (PolyFEM's JSON spec is the model). The scene parser (scene.cpp) validates
/// against it, `vesselverify scene --schema` prints it as JSON Schema, and docs/scene_reference.md
/// is generated from that schema (scripts/scene_reference.py).
#include <limits>
#include <string>
#include <vector>

namespace vessel {

enum class KeyType {
  string,   ///< a string; `choices` lists the accepted ones, if any
  boolean,  ///< true or false
  integer,  ///< an integer within [min, max]
  number,   ///< a finite number within the range (integers accepted)
  vector3,  ///< [x, y, z]
  vectors3,  ///< a non-empty array of [x, y, z]
  strings,  ///< a non-empty array of non-empty strings
  table,    ///< a [section] table (the top level's sections)
  tables,   ///< an array of tables ([[section]])
};

/// One key of one section. `variants` restricts it to some variants of its section (a model's
/// kind, a load's type, the vessel's form; SceneSection); empty: every variant.
struct SceneKey {
  std::string section;  ///< "" for the top level, else the table's name ("vessel", "models", ...)
  std::string name;
  KeyType type = KeyType::string;
  bool sweep = false;     ///< a value or a non-empty array of them (one run per value)
  bool required = false;  ///< in every variant it applies to
  /// The default as a TOML/JSON literal ("3e-3", "\"straight\"", "true"); empty: see
  /// `default_note` (a default that depends on other keys) or none.
  std::string default_value;
  std::string default_note;
  std::string unit;  ///< SI unit of the file's value (mm and mN where the key says so); "" if none
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;     ///< the value must exceed min (> 0: a positive number)
  std::vector<std::string> choices;   ///< string keys: the accepted values
  std::vector<std::string> variants;  ///< empty: all of the section's variants
  std::string doc;                    ///< one line

  [[nodiscard]] bool applies_to(const std::string& variant) const;
  /// What a value must be, as error messages and the reference say it: "a number > 0 m",
  /// "an integer in [0, 4] or an array of them", "one of clamped, roller, free".
  [[nodiscard]] std::string expected() const;
};

/// How a section's variant is chosen: by the value of its `selector` key (models: kind; load:
/// type) or by which of the `variants` keys is present (vessel: file, lumen; none: parametric).
struct SceneSection {
  std::string name;  ///< "" for the top level
  std::string doc;
  std::string selector;               ///< the key whose value names the variant; "" if by presence
  std::vector<std::string> variants;  ///< empty: one form only
  std::string default_variant;        ///< by presence: the variant when no variant key is present
};

/// Every section, the top level first, in the order of the reference.
const std::vector<SceneSection>& scene_sections();
/// Every key, grouped by section in scene_sections()'s order.
const std::vector<SceneKey>& scene_keys();
/// The key `name` of `section` in `variant` ("" for sections without variants); nullptr if the
/// key is not part of that variant.
const SceneKey* find_scene_key(const std::string& section, const std::string& name,
                               const std::string& variant);
/// The names of `section`'s keys in `variant`, in table order.
std::vector<std::string> scene_key_names(const std::string& section, const std::string& variant);

/// The table as a JSON Schema (draft 2020-12) of the scene file read as TOML → JSON. Each
/// property carries `description`, `default` (when literal), `x-unit` and `x-expected` (the
/// parser's wording of its range); variants are `if`/`then` clauses over the selector.
std::string scene_json_schema();

}  // namespace vessel
