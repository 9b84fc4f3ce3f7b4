// The calibrate operation's single-frame path ("mode": "apriltag"): one frame of
// tag36h11 AprilTags over the projector's framebuffer, one capture per camera, and the
// tag corners the first camera finds as the nodes of route (b′) ([Raskar02] §4.2.4: on a
// plane a collineation maps the projector's pixels to the camera's, and four points
// fix it; 32 tags give 128). On a worker; never touches daemon state.
#include <opencv2/core.hpp>

#include "calibration/plane_homography_route.hpp"
#include "calibration/two_view_plane.hpp"
#include "calibration_job.hpp"
#include "protocol.hpp"

namespace procam::daemon {

namespace code = proto::code;

tl::expected<CalibrationOutcome, CalibrationFailure> runTagCalibration(
    const CalibrationPlan& plan, const CalibrationHooks& hooks) {
  CalibrationOutcome out;
  auto settled = settleFor(plan, hooks, out);
  if (!settled) return tl::unexpected(settled.error());
  return tagFrameOutcome(plan, hooks, std::move(out), *settled);
}

tl::expected<TagViews, CalibrationFailure> captureTagFrame(const CalibrationPlan& plan,
                                                           const CalibrationHooks& hooks,
                                                           int settle_frames, double start) {
  const CalibrationFailure cancelled{code::kCancelled, "calibration cancelled"};
  if (!plan.tags || plan.cameras.empty()) {
    return calibrationFailed("internal: the tag frame needs the frame and a camera");
  }
  if (hooks.cancelled()) return tl::unexpected(cancelled);
  auto shown = showAndSettle(plan, plan.tags->rgb, "show the tag frame", settle_frames, hooks);
  if (!shown) return tl::unexpected(shown.error());
  if (!*shown) return tl::unexpected(cancelled);
  std::vector<cv::Mat> captures;
  for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
    auto grey = captureGray(plan.cameras[c].device);
    if (!grey) return tl::unexpected(grey.error());
    captures.push_back(std::move(*grey));
    // The coarse pass's captures (the adaptive path) came before.
    const int done = plan.captures() - static_cast<int>(plan.cameras.size() - c - 1);
    hooks.progress({start + (0.9 - start) * static_cast<double>(c + 1) /
                                static_cast<double>(plan.cameras.size()),
                    "capturing", done});
    if (hooks.cancelled()) return tl::unexpected(cancelled);
  }
  hooks.progress({0.9, "decoding", plan.captures()});
  // The first camera's corners are route (b′)'s nodes; a second camera's, with the
  // first's, triangulate the plane (the adaptive path with two cameras).
  const std::size_t used = plan.planar() ? 1 : plan.cameras.size();
  TagViews views;
  for (std::size_t c = 0; c < used; ++c) {
    const CalibrationCamera& cam = plan.cameras[c];
    const cv::Mat& seen = captures[c];
    if (seen.cols != cam.model.width || seen.rows != cam.model.height) {
      return calibrationFailed("captures of camera '" + cam.device.name + "' are " +
                               std::to_string(seen.cols) + "x" + std::to_string(seen.rows) +
                               " but its calibration is " + std::to_string(cam.model.width) + "x" +
                               std::to_string(cam.model.height));
    }
    auto found = findFiducials(*plan.tags, seen);
    if (!found) return calibrationFailed("camera '" + cam.device.name + "': " + found.error());
    if (found->empty()) {
      return calibrationFailed("camera '" + cam.device.name + "' found no tag of output '" +
                               plan.output.name + "': it does not see the projected tags");
    }
    views.push_back(std::move(*found));
  }
  return views;
}

tl::expected<void, CalibrationFailure> solveTagFrame(const CalibrationPlan& plan,
                                                     const TagViews& views,
                                                     const geom::Plane& plane,
                                                     CalibrationOutcome& out) {
  if (views.empty()) return calibrationFailed("internal: no camera's tag corners");
  const CalibrationCamera& cam = plan.cameras.front();
  for (const auto& corners : views) out.decoded.push_back(static_cast<int>(corners.size()));
  Points2 projector, camera;
  for (const drift::FiducialCorner& c : views.front()) {
    projector.push_back(c.drawn);
    camera.push_back(c.camera);
  }
  auto nodes = calib::collineationOfPoints(projector, camera, cam.model, cam.device.name);
  if (!nodes) return calibrationFailed(nodes.error().message);
  auto planar = calib::solvePlaneFromNodes(*nodes, cam.model, cam.device.name, plane,
                                           plan.set.options.width, plan.set.options.height);
  if (!planar) return calibrationFailed(planar.error().message);
  out.planar = std::move(*planar);
  return {};
}

Result<calib::TwoViewPlane> tagFramePlane(const CalibrationPlan& plan, const TagViews& views) {
  if (views.size() != 2 || plan.cameras.size() != 2) {
    return fail(ErrorCode::kInvalidInput, "the wall's plane from tags needs two cameras' corners");
  }
  // A corner both cameras found was drawn at the same framebuffer pixel.
  std::vector<calib::TwoViewPoint> both;
  for (const drift::FiducialCorner& a : views[0]) {
    for (const drift::FiducialCorner& b : views[1]) {
      if ((a.drawn - b.drawn).norm() < 1e-6) {
        both.push_back({a.camera, b.camera});
        break;
      }
    }
  }
  // The plane the run's other projectors were calibrated on, when these corners lie on it.
  const std::optional<geom::Plane> prior =
      plan.scene_plane ? *plan.scene_plane : std::optional<geom::Plane>();
  return calib::planeFromTwoViews(plan.cameras[0].model, plan.cameras[1].model, both,
                                  plan.cameras[0].device.name, plan.cameras[1].device.name, prior);
}

tl::expected<CalibrationOutcome, CalibrationFailure> tagFrameOutcome(const CalibrationPlan& plan,
                                                                     const CalibrationHooks& hooks,
                                                                     CalibrationOutcome out,
                                                                     double start) {
  if (!plan.plane) return calibrationFailed("internal: the tag frame is route (b′) with a plane");
  auto views = captureTagFrame(plan, hooks, out.settle_frames, start);
  if (!views) return tl::unexpected(views.error());
  hooks.progress({0.95, "solving", plan.captures()});
  auto solved = solveTagFrame(plan, *views, *plan.plane, out);
  if (!solved) return tl::unexpected(solved.error());
  return out;
}

}  // namespace procam::daemon
