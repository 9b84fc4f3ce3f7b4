#pragma once
// Triangle meshes of the virtual rig's objects, as a scanned or modelled object reaches
// shader lamps: the box of object_box and the vase (ball and neck) of object_vase, with
// texture coordinates, and a group per smooth part (a box face, the ball, the neck) so
// that checks can stay off the creases between parts.
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "geometry/intersect.hpp"

namespace procam::itest {

struct ObjectMesh {
  geom::TriangleMesh mesh;
  std::vector<Vec2> uv;    // per vertex
  std::vector<int> group;  // per face
};

// A grid of nu x nv quads over origin + s U + t V (s, t in [0, 1]), wound so that U x V
// is its outward normal; texture coordinates uv0 + (s, t) * uv_size.
inline void addGrid(ObjectMesh& m, const Vec3& origin, const Vec3& U, const Vec3& V, int nu, int nv,
                    int group, const Vec2& uv0, const Vec2& uv_size) {
  const int base = static_cast<int>(m.mesh.vertices.size());
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double s = static_cast<double>(i) / nu, t = static_cast<double>(j) / nv;
      m.mesh.vertices.push_back(origin + s * U + t * V);
      m.uv.push_back(uv0 + Vec2(s * uv_size.x(), t * uv_size.y()));
    }
  }
  const auto at = [&](int i, int j) { return base + j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      m.mesh.faces.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      m.mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
      m.group.push_back(group);
      m.group.push_back(group);
    }
  }
}

// An axis-aligned box in cells of about `cell` metres; face k's texture is cell
// (k % 3, k / 3) of a 3 x 2 atlas.
inline ObjectMesh boxMesh(const Vec3& center, const Vec3& size, double cell) {
  ObjectMesh m;
  const Vec3 h = 0.5 * size;
  const auto n = [&](double len) { return std::max(1, static_cast<int>(std::lround(len / cell))); };
  struct Face {
    Vec3 origin, U, V;
  };
  const Face faces[] = {
      {center + Vec3(-h.x(), -h.y(), h.z()), {size.x(), 0, 0}, {0, size.y(), 0}},    // +Z
      {center + Vec3(-h.x(), -h.y(), -h.z()), {0, size.y(), 0}, {size.x(), 0, 0}},   // -Z
      {center + Vec3(h.x(), -h.y(), -h.z()), {0, size.y(), 0}, {0, 0, size.z()}},    // +X
      {center + Vec3(-h.x(), -h.y(), -h.z()), {0, 0, size.z()}, {0, size.y(), 0}},   // -X
      {center + Vec3(-h.x(), h.y(), -h.z()), {0, 0, size.z()}, {size.x(), 0, 0}},    // +Y
      {center + Vec3(-h.x(), -h.y(), -h.z()), {size.x(), 0, 0}, {0, 0, size.z()}}};  // -Y
  for (int k = 0; k < 6; ++k) {
    const Face& f = faces[k];
    addGrid(m, f.origin, f.U, f.V, n(f.U.norm()), n(f.V.norm()), k,
            Vec2((k % 3) / 3.0, (k / 3) / 2.0), Vec2(1 / 3.0, 1 / 2.0));
  }
  return m;
}

// Faces around `center` turned to face away from it (a closed convex part's outside).
inline void windOutward(ObjectMesh& m, std::size_t first_face, const Vec3& center,
                        const Vec3& axis_or_zero) {
  for (std::size_t f = first_face; f < m.mesh.faces.size(); ++f) {
    auto& t = m.mesh.faces[f];
    const Vec3 a = m.mesh.vertices[t[0]], b = m.mesh.vertices[t[1]], c = m.mesh.vertices[t[2]];
    Vec3 out = (a + b + c) / 3 - center;
    if (!axis_or_zero.isZero()) out -= out.dot(axis_or_zero) * axis_or_zero;  // radial only
    if ((b - a).cross(c - a).dot(out) < 0) std::swap(t[1], t[2]);
  }
}

// The vase of object_vase: a ball (latitude-longitude, `segments` around) and a neck
// (an open tube); texture u around, v up: the ball in v [0, 0.7], the neck in [0.7, 1].
inline ObjectMesh vaseMesh(const Vec3& ball_center, double ball_radius, const Vec3& neck_base,
                           double neck_radius, double neck_height, int segments) {
  ObjectMesh m;
  const double pi = std::numbers::pi;
  const int rings = segments / 2;
  for (int j = 0; j <= rings; ++j) {
    const double theta = pi * j / rings;  // from the top
    for (int i = 0; i <= segments; ++i) {
      const double phi = 2 * pi * i / segments;
      m.mesh.vertices.push_back(ball_center + ball_radius * Vec3(std::sin(theta) * std::cos(phi),
                                                                 std::sin(theta) * std::sin(phi),
                                                                 std::cos(theta)));
      m.uv.emplace_back(static_cast<double>(i) / segments,
                        0.7 * (1 - static_cast<double>(j) / rings));
    }
  }
  const auto at = [&](int i, int j) { return j * (segments + 1) + i; };
  for (int j = 0; j < rings; ++j) {
    for (int i = 0; i < segments; ++i) {
      if (j > 0) {
        m.mesh.faces.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
        m.group.push_back(0);
      }
      if (j + 1 < rings) {
        m.mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
        m.group.push_back(0);
      }
    }
  }
  windOutward(m, 0, ball_center, Vec3::Zero());
  const std::size_t neck_first = m.mesh.faces.size();
  const int base = static_cast<int>(m.mesh.vertices.size());
  const int stacks = 8;
  for (int j = 0; j <= stacks; ++j) {
    for (int i = 0; i <= segments; ++i) {
      const double phi = 2 * pi * i / segments;
      m.mesh.vertices.push_back(neck_base + Vec3(neck_radius * std::cos(phi),
                                                 neck_radius * std::sin(phi),
                                                 neck_height * j / stacks));
      m.uv.emplace_back(static_cast<double>(i) / segments, 0.7 + 0.3 * j / stacks);
    }
  }
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < segments; ++i) {
      const int a = base + j * (segments + 1) + i;
      m.mesh.faces.emplace_back(a, a + 1, a + segments + 2);
      m.mesh.faces.emplace_back(a, a + segments + 2, a + segments + 1);
      m.group.push_back(1);
      m.group.push_back(1);
    }
  }
  windOutward(m, neck_first, neck_base, Vec3::UnitZ());
  return m;
}

// Which side of an axis-aligned box a normal belongs to (0 to 5).
inline int boxSideOf(const Vec3& n) {
  return n.x() > 0.5    ? 0
         : n.x() < -0.5 ? 1
         : n.y() > 0.5  ? 2
         : n.y() < -0.5 ? 3
         : n.z() > 0.5  ? 4
                        : 5;
}

// The mesh as an ASCII PLY with its texture coordinates (s t), its vertices in a model
// frame where world = R · model + t (the identity: world coordinates).
inline std::string texturedPly(const ObjectMesh& m, const Mat3& R = Mat3::Identity(),
                               const Vec3& t = Vec3::Zero()) {
  std::ostringstream ply;
  ply << "ply\nformat ascii 1.0\nelement vertex " << m.mesh.vertices.size()
      << "\nproperty double x\nproperty double y\nproperty double z\nproperty double s\n"
         "property double t\nelement face "
      << m.mesh.faces.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  ply.precision(17);
  for (std::size_t v = 0; v < m.mesh.vertices.size(); ++v) {
    const Vec3 x = R.transpose() * (m.mesh.vertices[v] - t);
    ply << x.x() << ' ' << x.y() << ' ' << x.z() << ' ' << m.uv[v].x() << ' ' << m.uv[v].y()
        << '\n';
  }
  for (const auto& f : m.mesh.faces) ply << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
  return ply.str();
}

}  // namespace procam::itest
