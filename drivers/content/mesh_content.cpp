#include "mesh_content.hpp"

#include <limits>

#include "sim/mesh_io.hpp"

namespace procam::content {

Result<MeshContent> loadMeshContent(const std::filesystem::path& file) {
  auto mesh = sim::loadMesh(file);
  if (!mesh) return tl::unexpected(mesh.error());
  // The reader refuses a mesh without faces: the bounds below are finite.
  MeshContent out;
  out.min = Vec3::Constant(std::numeric_limits<double>::infinity());
  out.max = -out.min;
  for (const auto& f : mesh->faces) {
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = mesh->vertices[static_cast<size_t>(f[k])];
      out.min = out.min.cwiseMin(v);
      out.max = out.max.cwiseMax(v);
    }
  }
  out.mesh = std::move(*mesh);
  return out;
}

}  // namespace procam::content
