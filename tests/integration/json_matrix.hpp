#pragma once
// A 3 x 4 matrix as status and display.json give it: twelve numbers, row by row.
#include <nlohmann/json.hpp>

#include "core/types.hpp"

namespace procam::itest {

inline Mat34 rowMajor34(const nlohmann::json& j) {
  Mat34 m;
  for (int i = 0; i < 12; ++i) m(i / 4, i % 4) = j[i].get<double>();
  return m;
}

}  // namespace procam::itest
