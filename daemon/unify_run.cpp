#include "unify_run.hpp"

#include "protocol.hpp"
#include "surface/mesh_unification.hpp"

namespace procam::daemon {

namespace code = proto::code;

tl::expected<nlohmann::json, CalibrationFailure> unifyRunMeshes(
    std::span<const CalibrationPlan* const> plans, std::span<CalibrationOutcome> outcomes) {
  std::vector<surface::UnifyProjector> meshes;
  std::vector<std::size_t> from;
  for (std::size_t i = 0; i < outcomes.size() && i < plans.size(); ++i) {
    const CalibrationOutcome& o = outcomes[i];
    if (o.planar || o.route.surface.planar || o.route.surface.mesh.faces.empty()) continue;
    geom::CameraModel projector;
    projector.K = o.route.projector.K;
    projector.pose = o.route.projector.pose;
    meshes.push_back({o.route.surface.mesh, projector.projectionMatrix(),
                      cv::Size(plans[i]->set.options.width, plans[i]->set.options.height)});
    from.push_back(i);
  }
  if (meshes.size() < 2) return nlohmann::json(nullptr);
  auto report = surface::unifyMeshes(meshes);
  if (!report) {
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "unifying the projectors' meshes: " + report.error().message});
  }
  for (std::size_t k = 0; k < from.size(); ++k) {
    outcomes[from[k]].route.surface.mesh = std::move(meshes[k].mesh);
  }
  return nlohmann::json{{"meshes", meshes.size()},
                        {"vertices", report->vertices},
                        {"shared", report->shared},
                        {"gap_rms_mm", 1000 * report->gap_rms_m},
                        {"gap_max_mm", 1000 * report->gap_max_m},
                        {"gap_after_rms_mm", 1000 * report->gap_after_rms_m},
                        {"gap_after_max_mm", 1000 * report->gap_after_max_m}};
}

}  // namespace procam::daemon
