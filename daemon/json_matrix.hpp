#pragma once
// Vectors and matrices as the protocol writes them: JSON arrays of numbers, matrices
// row-major.
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/types.hpp"

namespace procam::daemon {

inline nlohmann::json vectorJson(const Vec2& v) {
  return {v.x(), v.y()};
}

inline nlohmann::json vectorJson(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

// [x, y, z] of finite numbers; nullopt for anything else.
inline std::optional<Vec3> vectorFromJson(const nlohmann::json& j) {
  if (!j.is_array() || j.size() != 3) return std::nullopt;
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    if (!j[k].is_number() || !std::isfinite(j[k].get<double>())) return std::nullopt;
    v[k] = j[k].get<double>();
  }
  return v;
}

inline nlohmann::json rowMajor(const Mat34& m) {
  nlohmann::json v = nlohmann::json::array();
  for (int i = 0; i < 12; ++i) v.push_back(m(i / 4, i % 4));
  return v;
}

// [[a, b, c], [d, e, f], [g, h, i]]: a 3x3 matrix as rows (keystone homographies).
inline nlohmann::json matrixRows(const Mat3& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

inline nlohmann::json rowMajor(const Mat3& m) {
  nlohmann::json v = nlohmann::json::array();
  for (int i = 0; i < 9; ++i) v.push_back(m(i / 3, i % 3));
  return v;
}

}  // namespace procam::daemon
