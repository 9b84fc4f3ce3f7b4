#include "shader_lamps/object_placement.hpp"

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
  for (std::size_t i = 0; i < model_points.size(); ++i)
    out.max_m = std::max(out.max_m, (fit->R * model_points[i] + fit->t - world_points[i]).norm());
  return out;
}

geom::TriangleMesh placedMesh(const geom::TriangleMesh& model, const ObjectPlacement& p) {
  geom::TriangleMesh out = model;
  for (Vec3& v : out.vertices) v = p.R * v + p.t;
  return out;
}

}  // namespace procam::lamps
