#pragma once
// The double-precision ray cast of placed 3D content that the 3D content tests judge
// frames with: the nearest face along the viewer's ray (Möller–Trumbore, two-sided), and
// its Lambert grey as content/mesh_placement.hpp documents it.
#include <cmath>

#include "content/mesh_placement.hpp"

namespace procam::itest {

// Index of the nearest triangle of `m` hit by origin + l D (l > 0), or -1.
inline int nearestFace(const render::ColoredMesh& m, const Vec3& origin, const Vec3& D) {
  double best = INFINITY;
  int face = -1;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const Vec3 &a = m.vertices[m.triangles[t][0]], &b = m.vertices[m.triangles[t][1]],
               &c = m.vertices[m.triangles[t][2]];
    const Vec3 e1 = b - a, e2 = c - a, p = D.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-15) continue;
    const Vec3 s = origin - a, q = s.cross(e1);
    const double beta = s.dot(p) / det, gamma = D.dot(q) / det, l = e2.dot(q) / det;
    if (beta < 0 || gamma < 0 || beta + gamma > 1 || l <= 0 || l >= best) continue;
    best = l;
    face = static_cast<int>(t);
  }
  return face;
}

// Grey level 0..255 of a face: ambient plus two-sided Lambert under the fixed light
// l ~ -0.3 u + 0.5 v + 0.8 n of the placement's rectangle S.
inline double lambertGrey(const content::PlacedMesh& placed, int face) {
  const keystone::DisplayRect& S = placed.S;
  const Vec3 light = (-0.3 * S.u + 0.5 * S.v + 0.8 * S.u.cross(S.v)).normalized();
  const auto& m = placed.mesh;
  const auto& tri = m.triangles[static_cast<size_t>(face)];
  const Vec3 normal = (m.vertices[tri[1]] - m.vertices[tri[0]])
                          .cross(m.vertices[tri[2]] - m.vertices[tri[0]])
                          .normalized();
  return 255 * (content::kMeshAmbient + (1 - content::kMeshAmbient) * std::abs(normal.dot(light)));
}

}  // namespace procam::itest
