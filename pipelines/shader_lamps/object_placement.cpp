#include "shader_lamps/object_placement.hpp"

#include <cstdio>
#include <string>

#include "geometry/rigid.hpp"

namespace procam::lamps {

Result<ObjectPlacement> placeObject(std::span<const Vec3> model_points,
                                    std::span<const Vec3> world_points) {
  if (model_points.size() != world_points.size())
    return fail(ErrorCode::kInvalidInput, std::to_string(model_points.size()) +
                                              " model points for " +
                                              std::to_string(world_points.size()) + " in the rig");
  if (model_points.size() < kMinPlacementPoints)
    return fail(ErrorCode::kTooFewPoints, "placing an object needs at least " +
                                              std::to_string(kMinPlacementPoints) + " points");
  for (std::size_t i = 0; i < model_points.size(); ++i)
    if (!model_points[i].allFinite() || !world_points[i].allFinite())
      return fail(ErrorCode::kInvalidInput, "point " + std::to_string(i) + " is not finite");
  auto fit = geom::fitRigidTransform(model_points, world_points);
  if (!fit) return tl::unexpected(fit.error());
  ObjectPlacement out;
  out.R = fit->R;
  out.t = fit->t;
  out.rms_m = fit->rms;
  for (std::size_t i = 0; i < model_points.size(); ++i) {
    out.residuals_m.push_back((fit->R * model_points[i] + fit->t - world_points[i]).norm());
    out.max_m = std::max(out.max_m, out.residuals_m.back());
  }
  return out;
}

geom::TriangleMesh placedMesh(const geom::TriangleMesh& model, const ObjectPlacement& p) {
  geom::TriangleMesh out = model;
  for (Vec3& v : out.vertices) v = p.R * v + p.t;
  return out;
}

std::string modelPly(const geom::TriangleMesh& model) {
  const bool textured = model.texcoord.size() == model.vertices.size() && !model.vertices.empty();
  std::string out;
  out.reserve(128 + model.vertices.size() * 64 + model.faces.size() * 24);
  out += "ply\nformat ascii 1.0\ncomment procamd object model, model frame, metres\n";
  out += "element vertex " + std::to_string(model.vertices.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (textured) out += "property float s\nproperty float t\n";
  out += "element face " + std::to_string(model.faces.size()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  char line[160];
  for (std::size_t i = 0; i < model.vertices.size(); ++i) {
    const Vec3& x = model.vertices[i];
    int n = std::snprintf(line, sizeof line, "%.9g %.9g %.9g", x.x(), x.y(), x.z());
    if (textured)
      n += std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), " %.7g %.7g",
                         model.texcoord[i].x(), model.texcoord[i].y());
    out.append(line, static_cast<std::size_t>(n));
    out += '\n';
  }
  for (const auto& f : model.faces) {
    std::snprintf(line, sizeof line, "3 %d %d %d\n", f.x(), f.y(), f.z());
    out += line;
  }
  return out;
}

}  // namespace procam::lamps
