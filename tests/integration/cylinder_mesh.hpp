#pragma once
// cylinder3's true wall (unit/common/cylinder_wall.hpp) as a PLY file's text.
#include <sstream>
#include <string>

#include "unit/common/cylinder_wall.hpp"

namespace procam::itest {

inline std::string cylinderPly() {
  const geom::TriangleMesh mesh = testing_support::cylinderWall();
  std::ostringstream v, f;
  v.precision(12);
  for (const Vec3& p : mesh.vertices) v << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : mesh.faces) f << "3 " << t.x() << ' ' << t.y() << ' ' << t.z() << '\n';
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(mesh.vertices.size()) +
         "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
         std::to_string(mesh.faces.size()) +
         "\nproperty list uchar int vertex_indices\nend_header\n" + v.str() + f.str();
}

}  // namespace procam::itest
