#pragma once
// Test meshes: a subdivided icosahedron with every vertex on a sphere (20 * 4^k
// triangles) and a flat triangulated grid.
#include <cmath>
#include <map>
#include <utility>

#include "geometry/intersect.hpp"

namespace procam::test {

inline geom::TriangleMesh icosphere(const Vec3& center, double radius, int subdivisions) {
  const double p = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> v = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                         {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  for (Vec3& x : v) x.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<Eigen::Vector3i> next;
    next.reserve(f.size() * 4);
    for (const Eigen::Vector3i& t : f) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.emplace_back(t[0], ab, ca);
      next.emplace_back(t[1], bc, ab);
      next.emplace_back(t[2], ca, bc);
      next.emplace_back(ab, bc, ca);
    }
    f = std::move(next);
  }
  geom::TriangleMesh mesh;
  for (const Vec3& x : v) mesh.vertices.push_back(center + radius * x);
  mesh.faces = std::move(f);
  return mesh;
}

// n x n squares in the z = 0 plane covering [0, size]^2, two triangles each.
inline geom::TriangleMesh flatGrid(int n, double size) {
  geom::TriangleMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) mesh.vertices.emplace_back(size * i / n, size * j / n, 0.0);
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      mesh.faces.emplace_back(a, b, d);
      mesh.faces.emplace_back(a, d, c);
    }
  }
  return mesh;
}

}  // namespace procam::test
