#include "sim/toml_fields.hpp"

#include <cmath>
#include <sstream>

namespace procam::sim::detail {

namespace {
std::string numberText(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string rangeText(double lo, double hi, bool open_lo) {
  return std::string(open_lo ? "(" : "[") + numberText(lo) + ", " + numberText(hi) + "]";
}
}  // namespace

Fields::Fields(const toml::table& table, std::string path, const std::string* origin)
    : table_(&table), path_(std::move(path)), origin_(origin) {}

bool Fields::has(std::string_view key) const {
  return table_->contains(key);
}

std::string Fields::keyPath(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

std::string Fields::location(const toml::node* n) const {
  const auto line = n ? n->source().begin.line : table_->source().begin.line;
  return *origin_ + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": ";
}

void Fields::error(std::string_view key, const std::string& what) const {
  throw SceneFileError{location(table_->get(key)) + keyPath(key) + ": " + what};
}

void Fields::errorHere(const std::string& what) const {
  throw SceneFileError{location(nullptr) + (path_.empty() ? "" : path_ + ": ") + what};
}

const toml::node* Fields::node(std::string_view key) const {
  used_.insert(std::string(key));
  return table_->get(key);
}

double Fields::number(std::string_view key) const {
  const toml::node* n = node(key);
  if (!n) error(key, "required number is missing");
  const auto v = n->value<double>();
  if (!n->is_number() || !v) error(key, "expected a number");
  if (!std::isfinite(*v)) error(key, "must be finite");
  return *v;
}

double Fields::number(std::string_view key, double fallback) const {
  if (has(key)) return number(key);
  node(key);
  return fallback;
}

double Fields::requiredIn(std::string_view key, double lo, double hi, bool open_lo) const {
  const double v = number(key);
  if ((open_lo ? v <= lo : v < lo) || v > hi)
    error(key, "value " + numberText(v) + " outside " + rangeText(lo, hi, open_lo));
  return v;
}

double Fields::numberIn(std::string_view key, double fallback, double lo, double hi,
                        bool open_lo) const {
  if (!has(key)) {
    node(key);
    return fallback;
  }
  return requiredIn(key, lo, hi, open_lo);
}

int Fields::integerIn(std::string_view key, int fallback, int lo, int hi) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  if (!n->is_integer()) error(key, "expected an integer");
  const auto v = n->value<std::int64_t>().value_or(0);
  if (v < lo || v > hi)
    error(key, "value " + std::to_string(v) + " outside [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "]");
  return static_cast<int>(v);
}

bool Fields::boolean(std::string_view key, bool fallback) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  if (!n->is_boolean()) error(key, "expected true or false");
  return n->value<bool>().value_or(fallback);
}

std::string Fields::string(std::string_view key) const {
  const toml::node* n = node(key);
  if (!n) error(key, "required string is missing");
  if (!n->is_string()) error(key, "expected a string");
  std::string s = n->value<std::string>().value_or("");
  if (s.empty()) error(key, "must not be empty");
  return s;
}

std::optional<std::string> Fields::optionalString(std::string_view key) const {
  if (!has(key)) {
    node(key);
    return std::nullopt;
  }
  return string(key);
}

std::vector<double> Fields::numberArray(std::string_view key, std::size_t size) const {
  const toml::node* n = node(key);
  if (!n) error(key, "required array of " + std::to_string(size) + " numbers is missing");
  const toml::array* arr = n->as_array();
  if (!arr || arr->size() != size)
    error(key, "expected an array of " + std::to_string(size) + " numbers");
  std::vector<double> out;
  for (const auto& item : *arr) {
    const auto v = item.value<double>();
    if (!item.is_number() || !v || !std::isfinite(*v))
      error(key, "expected an array of " + std::to_string(size) + " finite numbers");
    out.push_back(*v);
  }
  return out;
}

Vec2 Fields::vec2(std::string_view key) const {
  const auto v = numberArray(key, 2);
  return {v[0], v[1]};
}

Vec3 Fields::vec3(std::string_view key) const {
  const auto v = numberArray(key, 3);
  return {v[0], v[1], v[2]};
}

std::optional<Vec3> Fields::optionalVec3(std::string_view key) const {
  if (!has(key)) {
    node(key);
    return std::nullopt;
  }
  return vec3(key);
}

Vec3 Fields::unitVec3(std::string_view key, const Vec3& fallback) const {
  if (!has(key)) {
    node(key);
    return fallback;
  }
  const Vec3 v = vec3(key);
  if (v.norm() < 1e-12) error(key, "direction must not be zero");
  return v.normalized();
}

Vec3 Fields::scalarOrVec3(std::string_view key, const Vec3& fallback, double lo, double hi) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  Vec3 v;
  if (n->is_number()) {
    v = Vec3::Constant(number(key));
  } else if (n->is_array()) {
    v = vec3(key);
  } else {
    error(key, "expected a number or an array of 3 numbers");
  }
  if (v.minCoeff() < lo || v.maxCoeff() > hi)
    error(key, "values must lie in " + rangeText(lo, hi, false));
  return v;
}

std::array<int, 2> Fields::resolution(std::string_view key) const {
  const toml::node* n = node(key);
  const toml::array* arr = n ? n->as_array() : nullptr;
  if (!arr || arr->size() != 2 || !(*arr)[0].is_integer() || !(*arr)[1].is_integer())
    error(key, "expected [width, height] as two integers");
  const auto w = (*arr)[0].value<std::int64_t>().value_or(0);
  const auto h = (*arr)[1].value<std::int64_t>().value_or(0);
  if (w < 1 || h < 1 || w > 16384 || h > 16384)
    error(key, "width and height must be in [1, 16384]");
  return {static_cast<int>(w), static_cast<int>(h)};
}

Mat3 Fields::matrix3(std::string_view key) const {
  const toml::node* n = node(key);
  const toml::array* rows = n ? n->as_array() : nullptr;
  if (!rows || rows->size() != 3) error(key, "expected 3 rows of 3 numbers");
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    const toml::array* row = (*rows)[static_cast<std::size_t>(r)].as_array();
    if (!row || row->size() != 3) error(key, "expected 3 rows of 3 numbers");
    for (int c = 0; c < 3; ++c) {
      const auto& item = (*row)[static_cast<std::size_t>(c)];
      const auto v = item.value<double>();
      if (!item.is_number() || !v || !std::isfinite(*v)) error(key, "expected finite numbers");
      m(r, c) = *v;
    }
  }
  return m;
}

Fields Fields::table(std::string_view key) const {
  const toml::node* n = node(key);
  if (!n) error(key, "required table is missing");
  if (!n->is_table()) error(key, "expected a table");
  return Fields(*n->as_table(), keyPath(key), origin_);
}

std::vector<Fields> Fields::tableArray(std::string_view key) const {
  std::vector<Fields> out;
  const toml::node* n = node(key);
  if (!n) return out;
  const toml::array* arr = n->as_array();
  if (!arr) error(key, "expected an array of tables ([[" + std::string(key) + "]])");
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::table* t = (*arr)[i].as_table();
    if (!t) error(key, "element " + std::to_string(i) + " is not a table");
    out.emplace_back(*t, keyPath(key) + "[" + std::to_string(i) + "]", origin_);
  }
  return out;
}

void Fields::finish() const {
  for (const auto& [key, value] : *table_) {
    if (!used_.contains(key.str())) {
      throw SceneFileError{location(&value) + "unknown key '" + keyPath(key.str()) + "'"};
    }
  }
}

}  // namespace procam::sim::detail
