#pragma once
// Small rigs for the shader-lamps unit tests: a projector looking along +Y at a square
// plate (a plane of two triangles, or a finer grid) at a known distance.
#include <cmath>

#include "geometry/camera_model.hpp"
#include "geometry/intersect.hpp"

namespace procam::lamps::test {

// A projector at `centre` looking at `target` (+Z up), 400 x 300 with f = 400 unless
// told, its principal point at the frame's centre.
inline geom::CameraModel projectorAt(const Vec3& centre, const Vec3& target, int width = 400,
                                     int height = 300, double f = 400) {
  geom::CameraModel m;
  m.width = width;
  m.height = height;
  m.K.fx = m.K.fy = f;
  m.K.cx = (width - 1) / 2.0;
  m.K.cy = (height - 1) / 2.0;
  m.pose = geom::Pose::lookAt(centre, target, Vec3::UnitZ());
  return m;
}

// The plate y = y0, x and z in [-half, half], n x n quads, facing -Y (towards y < y0).
inline geom::TriangleMesh plate(double y0, double half, int n) {
  geom::TriangleMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.vertices.emplace_back(-half + 2 * half * i / n, y0, -half + 2 * half * j / n);
  const auto at = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      m.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
      m.faces.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
    }
  }
  return m;
}

}  // namespace procam::lamps::test
