#pragma once
// Typed, checked access to the tables of a scene file. Every getter names the full
// key path (e.g. "cameras[1].bit_depth") and the line in its error; finish() rejects
// keys nobody asked for. Internal to the scene reader: failures are thrown as
// SceneFileError and turned into procam::Error by Scene::parse, never beyond it.
#include <toml++/toml.h>

#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.hpp"

namespace procam::sim::detail {

struct SceneFileError {
  std::string message;
};

class Fields {
 public:
  Fields(const toml::table& table, std::string path, const std::string* origin);

  bool has(std::string_view key) const;
  const std::string& path() const { return path_; }
  std::string keyPath(std::string_view key) const;

  double number(std::string_view key) const;
  double number(std::string_view key, double fallback) const;
  // Checked ranges: [lo, hi] inclusive unless open_lo.
  double numberIn(std::string_view key, double fallback, double lo, double hi,
                  bool open_lo = false) const;
  double requiredIn(std::string_view key, double lo, double hi, bool open_lo = false) const;
  int integerIn(std::string_view key, int fallback, int lo, int hi) const;
  bool boolean(std::string_view key, bool fallback) const;
  std::string string(std::string_view key) const;
  std::optional<std::string> optionalString(std::string_view key) const;

  Vec2 vec2(std::string_view key) const;
  Vec3 vec3(std::string_view key) const;
  std::optional<Vec3> optionalVec3(std::string_view key) const;
  Vec3 unitVec3(std::string_view key, const Vec3& fallback) const;  // normalised, non-zero
  // A scalar (same on all three) or a 3-element array, each in [lo, hi].
  Vec3 scalarOrVec3(std::string_view key, const Vec3& fallback, double lo, double hi) const;
  std::array<int, 2> resolution(std::string_view key) const;
  Mat3 matrix3(std::string_view key) const;

  Fields table(std::string_view key) const;                    // required sub-table
  std::vector<Fields> tableArray(std::string_view key) const;  // [[key]] or [{...}, ...]

  [[noreturn]] void error(std::string_view key, const std::string& what) const;
  [[noreturn]] void errorHere(const std::string& what) const;
  void finish() const;  // every key of the table must have been read

 private:
  const toml::node* node(std::string_view key) const;  // marks the key as used
  std::string location(const toml::node* n) const;
  std::vector<double> numberArray(std::string_view key, std::size_t size) const;

  const toml::table* table_;
  std::string path_;
  const std::string* origin_;
  mutable std::set<std::string, std::less<>> used_;
};

}  // namespace procam::sim::detail
