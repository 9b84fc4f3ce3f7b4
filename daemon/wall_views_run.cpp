#include "wall_views_run.hpp"

#include "protocol.hpp"

namespace procam::daemon {

namespace code = proto::code;

tl::expected<calib::WallViewsResult, CalibrationFailure> solveWallViewsRun(
    std::span<const CalibrationPlan* const> plans, std::span<CalibrationOutcome> outcomes) {
  if (plans.empty() || plans.size() != outcomes.size() || !plans.front()->wallViews()) {
    return tl::unexpected(
        CalibrationFailure{code::kFailed, "internal: no run of cameras at several positions"});
  }
  const CalibrationPlan& first = *plans.front();
  std::vector<std::pair<int, int>> sizes;
  std::vector<calib::WallNodes> nodes;
  for (std::size_t p = 0; p < plans.size(); ++p) {
    const CalibrationPlan& plan = *plans[p];
    if (!plan.wallViews() || plan.cameras.size() != first.cameras.size() ||
        outcomes[p].wall_nodes.size() != plan.cameras.size()) {
      return tl::unexpected(
          CalibrationFailure{code::kFailed, "internal: the run's projectors differ in cameras"});
    }
    sizes.emplace_back(plan.set.options.width, plan.set.options.height);
    for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
      if (outcomes[p].wall_nodes[c]) nodes.push_back({p, c, *outcomes[p].wall_nodes[c]});
    }
  }
  calib::WallViewsOptions options{.nodes = {.step = first.grid}, .reference_camera = 0};
  for (const auto& c : first.cameras)
    options.camera_names.push_back("camera '" + c.device.name + "'");
  for (const CalibrationPlan* p : plans) {
    options.projector_names.push_back("output '" + p->output.name + "'");
  }
  auto solved = calib::solveWallViews(sizes, first.cameras.size(), nodes, first.cameras[0].model,
                                      first.cameras[0].device.name, *first.plane, options);
  if (!solved) return tl::unexpected(CalibrationFailure{code::kFailed, solved.error().message});
  for (std::size_t p = 0; p < plans.size(); ++p) {
    calib::PlaneHomographyResult planar;
    planar.projector_to_plane = solved->projector_to_plane[p];
    const auto& stats = solved->projectors[p];
    planar.rms_camera_px = stats.rms_px;
    planar.coverage = stats.coverage;
    planar.samples = stats.samples;
    planar.inliers = stats.nodes;
    planar.rms_projector_px = stats.rms_projector_px;
    outcomes[p].planar = std::move(planar);
  }
  return std::move(*solved);
}

nlohmann::json wallViewsJson(const calib::WallViewsResult& result,
                             std::span<const CalibrationPlan* const> plans) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const auto& c : plans.front()->cameras) cameras.push_back(c.device.name);
  nlohmann::json links = nlohmann::json::array();
  for (std::size_t p = 0; p < result.projectors.size(); ++p) {
    links.push_back({{"output", plans[p]->output.name},
                     {"cameras", result.projectors[p].cameras},
                     {"nodes", result.projectors[p].nodes},
                     {"rms_camera_px", result.projectors[p].rms_px},
                     {"coverage", result.projectors[p].coverage},
                     {"chain_cameras", result.tree.chain_views[p]}});
  }
  return {{"reference_camera", plans.front()->cameras.front().device.name},
          {"cameras", cameras},
          {"links", result.tree.links},
          {"nodes", result.tree.matches},
          {"rms_camera_px", result.tree.rms_px},
          {"chain_rms_camera_px", result.tree.chain_rms_px},
          {"iterations", result.tree.iterations},
          {"converged", result.tree.converged},
          {"projectors", links}};
}

}  // namespace procam::daemon
