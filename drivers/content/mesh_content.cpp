#include "mesh_content.hpp"

#include <limits>

namespace procam::content {

namespace {

Result<MeshContent> bounded(Result<geom::TriangleMesh> mesh) {
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

}  // namespace

Result<MeshContent> loadMeshContent(const std::filesystem::path& file,
                                    const sim::MeshLimits& limits) {
  return bounded(sim::loadMesh(file, limits));
}

Result<MeshContent> meshContentFromBytes(std::string_view bytes, const std::string& name,
                                         const sim::MeshLimits& limits) {
  return bounded(sim::parseMesh(bytes, name, limits));
}

}  // namespace procam::content
