#pragma once
// Vectors and matrices as the protocol writes them: JSON arrays of numbers, matrices
// row-major.
#include <nlohmann/json.hpp>

#include "core/types.hpp"

namespace procam::daemon {

inline nlohmann::json vectorJson(const Vec2& v) {
  return {v.x(), v.y()};
}

inline nlohmann::json vectorJson(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

inline nlohmann::json rowMajor(const Mat34& m) {
  nlohmann::json v = nlohmann::json::array();
  for (int i = 0; i < 12; ++i) v.push_back(m(i / 4, i % 4));
  return v;
}

inline nlohmann::json rowMajor(const Mat3& m) {
  nlohmann::json v = nlohmann::json::array();
  for (int i = 0; i < 9; ++i) v.push_back(m(i / 3, i % 3));
  return v;
}

}  // namespace procam::daemon
