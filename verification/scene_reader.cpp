#include "verification/scene_reader.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "meshes/foundation/errors.hpp"

namespace vessel::scene_detail {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// The items of a sweep key's value: the array's, or the value itself.
std::vector<const toml::node*> items_of(const toml::node& n) {
  std::vector<const toml::node*> items;
  if (const auto* arr = n.as_array()) {
    for (const auto& item : *arr) items.push_back(&item);
  } else {
    items.push_back(&n);
  }
  return items;
}

/// What a missing key should have been: its range, and what it is.
std::string missing_text(const SceneKey& k) {
  if (k.type == KeyType::table) return "missing; expected a [" + k.name + "] table";
  if (k.type == KeyType::tables) return "missing; expected at least one [[" + k.name + "]] table";
  std::string doc = k.doc;
  if (!doc.empty()) doc[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(doc[0])));
  return "missing; expected " + k.expected() + " (" + doc + ")";
}

}  // namespace

std::string show(const toml::node& node) {
  std::ostringstream s;
  node.visit([&](auto&& v) {
    using T = std::remove_cvref_t<decltype(v)>;
    if constexpr (toml::is_string<T>) {
      s << '"' << *v << '"';
    } else if constexpr (toml::is_table<T>) {
      s << "a table";
    } else if constexpr (toml::is_array<T>) {
      s << "an array";
    } else if constexpr (toml::is_boolean<T>) {
      s << (*v ? "true" : "false");
    } else if constexpr (toml::is_floating_point<T>) {
      s << number_text(*v);
    } else {
      s << *v;  // integers, dates and times
    }
  });
  return s.str();
}

TableReader::TableReader(const toml::table& table, std::string section, std::string prefix,
                         std::string file)
    : table_(table),
      section_(std::move(section)),
      prefix_(std::move(prefix)),
      file_(std::move(file)) {
  for (const auto& s : scene_sections()) {
    if (s.name == section_ && s.variants.empty()) enter("");
  }
}

void TableReader::enter(const std::string& variant) {
  variant_ = variant;
  for (const auto& [key, node] : table_) {
    const std::string k(key.str());
    if (!find_scene_key(section_, k, variant_)) {
      fail(&node, k, "unknown key; expected one of: " + join(scene_key_names(section_, variant_)));
    }
  }
  // Required sections are checked when read (sub), so that a section's own errors come first.
  for (const SceneKey& k : scene_keys()) {
    if (k.section == section_ && k.required && k.applies_to(variant_) && !table_.get(k.name) &&
        k.type != KeyType::table && k.type != KeyType::tables) {
      fail(nullptr, k.name, missing_text(k));
    }
  }
}

void TableReader::fail(const toml::node* node, const std::string& key,
                       const std::string& what) const {
  const auto line = node ? node->source().begin.line : table_.source().begin.line;
  const std::string where = key.empty() ? "[" + prefix_.substr(0, prefix_.size() - 1) + "]"
                                        : "key '" + prefix_ + key + "'";
  throw InputError(file_ + ":" + std::to_string(line) + ": " + where + ": " + what);
}

void TableReader::fail_value(const toml::node& n, const std::string& key,
                             const std::string& found) const {
  fail(&n, key, "found " + found + ", expected " + spec(key).expected());
}

const SceneKey& TableReader::spec(const std::string& key) const {
  const SceneKey* k = find_scene_key(section_, key, variant_);
  if (!k) {
    throw std::logic_error("scene parser: key '" + section_ + "." + key + "' (" + variant_ +
                           ") is not in the scene table (scene_keys.cpp)");
  }
  return *k;
}

const toml::node* TableReader::get(const std::string& key) const {
  (void)spec(key);
  return table_.get(key);
}

const toml::node& TableReader::require(const std::string& key) const {
  const toml::node* n = get(key);
  if (!n) fail(nullptr, key, missing_text(spec(key)));
  return *n;
}

double TableReader::number(const toml::node& n, const std::string& key) const {
  const SceneKey& k = spec(key);
  std::optional<double> v;
  if (n.is_floating_point() || n.is_integer()) v = n.value<double>();
  if (!v) fail_value(n, key, show(n));
  if (!std::isfinite(*v) || *v < k.min || *v > k.max || (k.min_exclusive && *v <= k.min)) {
    fail_value(n, key, number_text(*v));
  }
  return *v;
}

double TableReader::number_or(const std::string& key, double fallback) const {
  const toml::node* n = get(key);
  return n ? number(*n, key) : fallback;
}

double TableReader::number_or(const std::string& key) const {
  const SceneKey& k = spec(key);
  if (k.default_value.empty()) throw std::logic_error("scene table: no default for " + key);
  return number_or(key, std::stod(k.default_value));
}

std::vector<double> TableReader::numbers(const toml::node& n, const std::string& key) const {
  if (const auto* arr = n.as_array(); arr && arr->empty()) fail_value(n, key, "an empty array");
  if (n.is_array() && !spec(key).sweep) fail_value(n, key, "an array");
  std::vector<double> out;
  for (const toml::node* item : items_of(n)) out.push_back(number(*item, key));
  return out;
}

long TableReader::integer_or(const std::string& key, long fallback) const {
  const toml::node* n = get(key);
  if (!n) return fallback;
  const SceneKey& k = spec(key);
  const auto v = n->value_exact<int64_t>();
  if (!v || double(*v) < k.min || double(*v) > k.max) fail_value(*n, key, show(*n));
  return static_cast<long>(*v);
}

std::vector<int> TableReader::integers_or(const std::string& key, std::vector<int> fallback) const {
  const toml::node* n = get(key);
  if (!n) return fallback;
  if (const auto* arr = n->as_array(); arr && arr->empty()) fail_value(*n, key, "an empty array");
  const SceneKey& k = spec(key);
  std::vector<int> out;
  for (const toml::node* item : items_of(*n)) {
    const auto v = item->value_exact<int64_t>();
    if (!v || double(*v) < k.min || double(*v) > k.max) fail_value(*item, key, show(*item));
    out.push_back(static_cast<int>(*v));
  }
  return out;
}

bool TableReader::boolean_or(const std::string& key) const {
  const toml::node* n = get(key);
  if (!n) return spec(key).default_value == "true";
  const auto v = n->value_exact<bool>();
  if (!v) fail_value(*n, key, show(*n));
  return *v;
}

std::string TableReader::checked_string(const toml::node& n, const std::string& key) const {
  const SceneKey& k = spec(key);
  const auto v = n.value_exact<std::string>();
  if (!v) {
    const std::string choices = k.choices.empty() ? "" : " (" + k.expected() + ")";
    fail(&n, key, "found " + show(n) + ", expected a string" + choices);
  }
  if (!k.choices.empty() && std::find(k.choices.begin(), k.choices.end(), *v) == k.choices.end()) {
    fail(&n, key, "found \"" + *v + "\", expected " + k.expected());
  }
  return *v;
}

std::string TableReader::string_or(const std::string& key, const std::string& fallback) const {
  const toml::node* n = get(key);
  if (n && n->is_array()) fail(n, key, "found an array, expected one string");
  return n ? checked_string(*n, key) : fallback;
}

std::string TableReader::default_string(const std::string& key) const {
  const std::string& literal = spec(key).default_value;
  if (literal.size() < 2 || literal.front() != '"') {
    throw std::logic_error("scene table: no string default for " + key);
  }
  return literal.substr(1, literal.size() - 2);
}

std::string TableReader::string_or(const std::string& key) const {
  return string_or(key, default_string(key));
}

std::vector<std::string> TableReader::strings_or(const std::string& key,
                                                 const std::string& fallback) const {
  const toml::node* n = get(key);
  if (!n) return {fallback};
  if (const auto* arr = n->as_array(); arr && arr->empty()) {
    fail(n, key, "found an empty array, expected at least one name");
  }
  std::vector<std::string> out;
  for (const toml::node* item : items_of(*n)) out.push_back(checked_string(*item, key));
  return out;
}

std::vector<std::string> TableReader::string_array(const std::string& key) const {
  const toml::node& n = require(key);
  const auto* arr = n.as_array();
  if (!arr || arr->empty()) fail_value(n, key, show(n));
  std::vector<std::string> out;
  for (const auto& item : *arr) {
    const auto v = item.value_exact<std::string>();
    if (!v || v->empty()) fail_value(item, key, show(item));
    out.push_back(*v);
  }
  return out;
}

Vec3 TableReader::vector3(const toml::node& n, const std::string& key) const {
  const auto* arr = n.as_array();
  if (!arr || arr->size() != 3) fail_value(n, key, show(n));
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    const toml::node& item = *arr->get(i);
    if (!(item.is_floating_point() || item.is_integer()) || !std::isfinite(*item.value<double>())) {
      fail_value(item, key, show(item));
    }
    v[i] = *item.value<double>();
  }
  return v;
}

std::vector<Vec3> TableReader::vectors3(const toml::node& n, const std::string& key) const {
  const auto* arr = n.as_array();
  if (!arr || arr->empty()) fail_value(n, key, show(n));
  std::vector<Vec3> out;
  for (const auto& item : *arr) out.push_back(vector3(item, key));
  return out;
}

TableReader TableReader::sub(const std::string& key) const {
  const toml::node* n = get(key);
  if (!n && spec(key).required) fail(nullptr, key, missing_text(spec(key)));
  if (!n) return TableReader(empty_, key, prefix_ + key + ".", file_);
  if (!n->is_table()) fail_value(*n, key, show(*n));
  return TableReader(*n->as_table(), key, prefix_ + key + ".", file_);
}

}  // namespace vessel::scene_detail
