#pragma once
// Pinhole matrices and surfaces for render tests, built independently of the code under
// test (frames per ARCHITECTURE.md: x right, y down, z forward; P = K [R | t]).
#include <cmath>
#include <optional>

#include "core/types.hpp"
#include "render/projective_mesh.hpp"

namespace procam::test {

inline Mat34 lookAtProjection(double f, double cx, double cy, const Vec3& eye, const Vec3& target,
                              const Vec3& up) {
  const Vec3 z = (target - eye).normalized();
  const Vec3 x = z.cross(up).normalized();  // right: forward x up points right with y down
  const Vec3 y = z.cross(x);
  Mat3 R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  Mat3 K;
  K << f, 0, cx, 0, f, cy, 0, 0, 1;
  Mat34 Rt;
  Rt << R, -R * eye;
  return K * Rt;
}

// Ray through pixel (x, y) of P = K [R | t]: origin and direction in world.
inline void pixelRay(const Mat34& P, double x, double y, Vec3& origin, Vec3& dir) {
  const Mat3 M = P.leftCols<3>();
  origin = -M.inverse() * P.col(3);
  dir = (M.inverse() * Vec3(x, y, 1)).normalized();
}

// Nearest ray-mesh hit (Moller-Trumbore), t > 0.
inline std::optional<Vec3> intersect(const render::SurfaceMesh& mesh, const Vec3& o,
                                     const Vec3& d) {
  double best = INFINITY;
  for (const auto& tri : mesh.triangles) {
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    const Vec3 e1 = b - a, e2 = c - a, p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-15) continue;
    const Vec3 s = o - a;
    const double u = s.dot(p) / det;
    const Vec3 q = s.cross(e1);
    const double v = d.dot(q) / det;
    const double t = e2.dot(q) / det;
    if (u < -1e-12 || v < -1e-12 || u + v > 1 + 1e-12 || t <= 0) continue;
    best = std::min(best, t);
  }
  if (!std::isfinite(best)) return std::nullopt;
  return o + best * d;
}

// Rectangle in the plane through `c` spanned by unit axes u, v, split in n x n cells.
inline render::SurfaceMesh planeMesh(const Vec3& c, const Vec3& u, const Vec3& v, double half_w,
                                     double half_h, int n) {
  render::SurfaceMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.vertices.push_back(c + (2.0 * i / n - 1) * half_w * u + (2.0 * j / n - 1) * half_h * v);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      m.triangles.push_back({a, a + 1, a + n + 2});
      m.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  }
  return m;
}

// Inside of a hemisphere of radius r centred at c with its pole along +Y (a dome seen
// from inside), tessellated in rings x sectors.
inline render::SurfaceMesh domeMesh(const Vec3& c, double r, int rings, int sectors) {
  render::SurfaceMesh m;
  for (int i = 0; i <= rings; ++i) {
    const double polar = (M_PI / 2) * i / rings;  // 0 at the pole
    for (int k = 0; k <= sectors; ++k) {
      const double az = 2 * M_PI * k / sectors;
      m.vertices.push_back(c + r * Vec3(std::sin(polar) * std::cos(az), std::cos(polar),
                                        std::sin(polar) * std::sin(az)));
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int k = 0; k < sectors; ++k) {
      const int a = i * (sectors + 1) + k, b = a + sectors + 1;
      m.triangles.push_back({a, b, a + 1});
      m.triangles.push_back({a + 1, b, b + 1});
    }
  }
  return m;
}

}  // namespace procam::test
