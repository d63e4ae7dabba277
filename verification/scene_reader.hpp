#pragma once
/// The scene parser's reader of one TOML table, checked against the scene table (scene_keys.hpp):
/// every key must be the table's, in the section's variant; every value must have the key's
/// type and range. Messages say "file:line: key 'a.b': found X, expected Y". Private to the scene
/// parser (scene.cpp).
#include <string>
#include <vector>
#include <toml++/toml.h>

#include "meshes/tet_mesh.hpp"
#include "verification/scene_keys.hpp"

namespace vessel::scene_detail {

/// A TOML value as a message quotes it: "\"3mm\"", "0.6", "a table".
std::string show(const toml::node& node);

class TableReader {
 public:
  /// `section` names the table's rows in scene_keys(); `prefix` is how messages name its keys
  /// ("models[1]."). A section without variants is checked at once; one with variants when
  /// its variant is known (enter).
  TableReader(const toml::table& table, std::string section, std::string prefix, std::string file);

  /// Sets the variant (a model's kind, a load's type, the vessel's form) and checks the table:
  /// its first key not in the variant is an unknown key, a required value absent is missing (a
  /// required section is checked when read, by sub).
  void enter(const std::string& variant);

  [[noreturn]] void fail(const toml::node* node, const std::string& key,
                         const std::string& what) const;

  /// The key's row; a key the table does not declare for this variant is the parser's bug.
  const SceneKey& spec(const std::string& key) const;
  /// The key's node, or nullptr when absent (the key must be declared).
  const toml::node* get(const std::string& key) const;
  const toml::node& require(const std::string& key) const;

  /// A number within the key's range.
  double number(const toml::node& n, const std::string& key) const;
  /// The key's number, or `fallback` when absent; without a fallback, the table's default.
  double number_or(const std::string& key, double fallback) const;
  double number_or(const std::string& key) const;
  /// A number or a non-empty array of numbers (a sweep key), each within the key's range.
  std::vector<double> numbers(const toml::node& n, const std::string& key) const;

  long integer_or(const std::string& key, long fallback) const;
  /// An integer or a non-empty array of integers, each within the key's range.
  std::vector<int> integers_or(const std::string& key, std::vector<int> fallback) const;

  bool boolean_or(const std::string& key) const;
  /// A string (one of the key's choices, if it has them), or `fallback` when absent.
  std::string string_or(const std::string& key, const std::string& fallback) const;
  /// The table's default when absent.
  std::string string_or(const std::string& key) const;
  /// The table's default of a string key, unquoted.
  std::string default_string(const std::string& key) const;
  /// A string or a non-empty array of strings (a sweep key), each one of the key's choices.
  std::vector<std::string> strings_or(const std::string& key, const std::string& fallback) const;
  /// A non-empty array of non-empty strings (KeyType::strings).
  std::vector<std::string> string_array(const std::string& key) const;
  Vec3 vector3(const toml::node& n, const std::string& key) const;
  /// A non-empty array of [x, y, z] (KeyType::vectors3).
  std::vector<Vec3> vectors3(const toml::node& n, const std::string& key) const;

  /// The sub-table `key` (an empty one when absent; missing if required).
  TableReader sub(const std::string& key) const;

  const toml::table& table() const { return table_; }
  const std::string& prefix() const { return prefix_; }
  const std::string& file() const { return file_; }

 private:
  [[noreturn]] void fail_value(const toml::node& n, const std::string& key,
                               const std::string& found) const;
  std::string checked_string(const toml::node& n, const std::string& key) const;

  inline static const toml::table empty_{};
  const toml::table& table_;
  std::string section_;
  std::string prefix_;
  std::string file_;
  std::string variant_;
};

}  // namespace vessel::scene_detail
