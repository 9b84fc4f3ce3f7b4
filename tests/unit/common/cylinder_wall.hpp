#pragma once
// cylinder3's wall (radius 3 m about Z, 0-3.5 m high) as a mesh of 0.25 deg facets over
// the 240 deg facing +Y: its chords lie within 7 um of the true wall. For tests that
// hand a pipeline, procamd or procam-render the TRUE surface.
#include <numbers>

#include "geometry/intersect.hpp"

namespace procam::testing_support {

inline geom::TriangleMesh cylinderWall() {
  geom::TriangleMesh mesh;
  constexpr int kAround = 960, kUp = 14;
  for (int i = 0; i <= kAround; ++i) {
    const double a = (-120.0 + 240.0 * i / kAround) * std::numbers::pi / 180;
    for (int j = 0; j <= kUp; ++j)
      mesh.vertices.emplace_back(3 * std::sin(a), 3 * std::cos(a), 3.5 * j / kUp);
  }
  for (int i = 0; i < kAround; ++i) {
    for (int j = 0; j < kUp; ++j) {
      const int v = i * (kUp + 1) + j;
      mesh.faces.emplace_back(v, v + kUp + 1, v + 1);
      mesh.faces.emplace_back(v + 1, v + kUp + 1, v + kUp + 2);
    }
  }
  return mesh;
}

}  // namespace procam::testing_support
