// The calibrate operation's single-frame path ("mode": "apriltag"): one frame of
// tag36h11 AprilTags over the projector's framebuffer, one capture per camera, and the
// tag corners the first camera finds as the nodes of route (b′) ([Raskar02] §4.2.4: on a
// plane one collineation maps the projector's pixels to the camera's, and four points
// fix it; 32 tags give 128). On a worker; never touches daemon state.
#include <opencv2/core.hpp>

#include "calibration/plane_homography_route.hpp"
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

tl::expected<CalibrationOutcome, CalibrationFailure> tagFrameOutcome(const CalibrationPlan& plan,
                                                                     const CalibrationHooks& hooks,
                                                                     CalibrationOutcome out,
                                                                     double start) {
  const CalibrationFailure cancelled{code::kCancelled, "calibration cancelled"};
  const auto failed = [&](const std::string& why) {
    return tl::unexpected(CalibrationFailure{code::kFailed, why});
  };
  if (!plan.tags || !plan.plane || plan.cameras.empty()) {
    return failed("internal: the tag frame is route (b′) with a camera and a plane");
  }
  if (hooks.cancelled()) return tl::unexpected(cancelled);
  auto shown = showAndSettle(plan, plan.tags->rgb, "show the tag frame", out.settle_frames, hooks);
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
  const int total = plan.captures();
  hooks.progress({0.9, "decoding", total});
  const CalibrationCamera& cam = plan.cameras.front();
  const cv::Mat& seen = captures.front();
  if (seen.cols != cam.model.width || seen.rows != cam.model.height) {
    return failed("captures of camera '" + cam.device.name + "' are " + std::to_string(seen.cols) +
                  "x" + std::to_string(seen.rows) + " but its calibration is " +
                  std::to_string(cam.model.width) + "x" + std::to_string(cam.model.height));
  }
  auto found = findFiducials(*plan.tags, seen);
  if (!found) return failed("camera '" + cam.device.name + "': " + found.error());
  out.decoded.push_back(static_cast<int>(found->size()));
  if (found->empty()) {
    return failed("camera '" + cam.device.name + "' found no tag of output '" + plan.output.name +
                  "': it does not see the projected tags");
  }
  hooks.progress({0.95, "solving", total});
  Points2 projector, camera;
  for (const drift::FiducialCorner& c : *found) {
    projector.push_back(c.drawn);
    camera.push_back(c.camera);
  }
  auto nodes = calib::collineationOfPoints(projector, camera, cam.model, cam.device.name);
  if (!nodes) return failed(nodes.error().message);
  auto planar = calib::solvePlaneFromNodes(*nodes, cam.model, cam.device.name, *plan.plane,
                                           plan.set.options.width, plan.set.options.height);
  if (!planar) return failed(planar.error().message);
  out.planar = std::move(*planar);
  return out;
}

}  // namespace procam::daemon
