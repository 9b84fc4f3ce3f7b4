// The calibrate operation's adaptive path ("mode": "adaptive"): skip what the scene does
// not need ([Raskar02] §4.1.4 starts from a coarse 16x12 binary-coded pass). The coarse
// Gray pass tells whether the surface is planar (a plane seen through the projector is
// one homography, §3.2.5); on a plane one AprilTag frame then gives the collineation
// route (b′) needs (tag_calibration_job.cpp), 19 frames in all where the full scan
// shows 50. With one camera the plane is given (the request's or the rig's) and a
// surface that is not planar is refused, as route (b′) would calibrate it wrongly; with
// two calibrated cameras the tag corners both find triangulate the plane, and a surface
// that is not planar gets the full scan of route (a), the coarse pass its only extra
// cost. On a worker; never touches daemon state.
#include <opencv2/imgproc.hpp>

#include "calibration_job.hpp"
#include "protocol.hpp"
#include "structured_light/adaptive_scan.hpp"
#include "structured_light/decoder.hpp"

namespace procam::daemon {

namespace code = proto::code;
using nlohmann::json;

namespace {

using Outcome = tl::expected<CalibrationOutcome, CalibrationFailure>;

// The coarse pass's blocks in one camera tested for one homography, in its ideal pixels
// (lens distortion bends a plane's image off one homography).
Result<sl::PlanarityTest> coarseTest(const sl::PatternSet& coarse, const sl::Decoded& decoded,
                                     const CalibrationCamera& cam) {
  sl::AdaptiveOptions options;
  options.full.width = coarse.options.width;
  options.full.height = coarse.options.height;
  options.undistort = [&model = cam.model](const Vec2& px) {
    auto ideal = model.undistortPixel(px);
    return ideal ? *ideal : px;
  };
  return sl::testPlanarity(coarse, decoded, options);
}

// The full scan of route (a) after the coarse pass (and perhaps the tag frame) of the
// adaptive pair: the plan's pattern set with the settle frames already found, its
// progress and captures counted on from `start` and `done`.
Outcome fullScanAfter(const CalibrationPlan& plan, const CalibrationHooks& hooks,
                      CalibrationOutcome coarse_out, double start, int done) {
  CalibrationPlan full = plan;
  full.tags.reset();
  full.coarse.reset();
  full.settle_frames = coarse_out.settle_frames;
  full.auto_settle = false;
  const int total = done + full.captures();
  CalibrationHooks counted{
      hooks.cancelled, [&](const CalibrationProgress& p) {
        // Up to 0.97 of the run: writing the result comes after.
        hooks.progress({start + (0.97 - start) * p.fraction, p.stage, done + p.capture, total});
      }};
  auto result = runCalibration(full, counted);
  if (!result) return result;
  result->latency = std::move(coarse_out.latency);
  result->coarse = std::move(coarse_out.coarse);
  result->coarse["full_frames"] = static_cast<int>(full.set.frames.size());
  return result;
}

}  // namespace

Outcome runAdaptiveCalibration(const CalibrationPlan& plan, const CalibrationHooks& hooks) {
  const CalibrationFailure cancelled{code::kCancelled, "calibration cancelled"};
  if (!plan.coarse || !plan.tags || plan.cameras.empty() || (!plan.plane && !plan.adaptivePair())) {
    return calibrationFailed(
        "internal: the adaptive path is route (b′) with a camera and a plane, or two cameras");
  }
  const sl::PatternSet& coarse = *plan.coarse;
  CalibrationOutcome out;
  auto settled = settleFor(plan, hooks, out);
  if (!settled) return tl::unexpected(settled.error());
  const double start = *settled;
  // The coarse pass takes this share of the progress; the tag frame the rest.
  const double coarse_end = start + (0.9 - start) * 0.9;
  const std::size_t cameras = plan.cameras.size();
  const double coarse_captures = static_cast<double>(coarse.frames.size() * cameras);
  std::vector<std::vector<cv::Mat>> captures(cameras);
  int done = 0;
  for (std::size_t f = 0; f < coarse.frames.size(); ++f) {
    if (hooks.cancelled()) return tl::unexpected(cancelled);
    cv::Mat rgb;
    cv::cvtColor(sl::renderFrame(coarse, f), rgb, cv::COLOR_GRAY2RGB);
    auto shown = showAndSettle(plan, rgb, "show a coarse pattern", out.settle_frames, hooks);
    if (!shown) return tl::unexpected(shown.error());
    if (!*shown) return tl::unexpected(cancelled);
    for (std::size_t c = 0; c < cameras; ++c) {
      auto grey = captureGray(plan.cameras[c].device);
      if (!grey) return tl::unexpected(grey.error());
      captures[c].push_back(std::move(*grey));
      ++done;
      hooks.progress({start + (coarse_end - start) * done / coarse_captures, "capturing", done});
    }
  }
  // Every camera tests the blocks it sees: the surface is planar when each finds one
  // homography. The first camera's fit is reported, and with two cameras each one's.
  bool planar = true;
  std::string why_not;  // the first fit that found the surface not planar
  json fits = json::array();
  for (std::size_t c = 0; c < cameras; ++c) {
    const CalibrationCamera& cam = plan.cameras[c];
    auto decoded = sl::decode(coarse, captures[c]);
    if (!decoded)
      return calibrationFailed("camera '" + cam.device.name + "': " + decoded.error().message);
    auto test = coarseTest(coarse, *decoded, cam);
    if (!test) {
      return calibrationFailed("the coarse pass: camera '" + cam.device.name +
                               "': " + test.error().message);
    }
    const json fit = {{"blocks", test->camera.size()},
                      {"rms_px", test->rms_px},
                      {"tolerance_px", test->tolerance_px}};
    if (c == 0) out.coarse = fit;
    json view = {{"camera", cam.device.name}, {"planar", test->planar}};
    view.update(fit);
    fits.push_back(std::move(view));
    if (!test->planar && planar) {
      planar = false;
      why_not = "the coarse pass finds the surface not planar (camera '" + cam.device.name +
                "': its " + std::to_string(test->camera.size()) + " blocks fit one homography to " +
                std::to_string(test->rms_px) + " projector px RMS, over the " +
                std::to_string(test->tolerance_px) + " px a plane allows)";
    }
  }
  out.coarse["frames"] = static_cast<int>(coarse.frames.size());
  out.coarse["planar"] = planar;
  if (cameras > 1) out.coarse["views"] = std::move(fits);
  if (!planar && !plan.adaptivePair()) {
    return calibrationFailed(
        why_not +
        ": route (b′) needs a plane; with two calibrated cameras and no plane the adaptive "
        "path scans it fully (route (a))");
  }
  if (!planar) {
    out.coarse["then"] = "the full scan: " + why_not;
    return fullScanAfter(plan, hooks, std::move(out), coarse_end, done);
  }
  if (plan.plane) return tagFrameOutcome(plan, hooks, std::move(out), coarse_end);

  // The adaptive pair on a plane: the tag frame's corners both cameras find give the
  // plane, the first camera's the collineation.
  auto views = captureTagFrame(plan, hooks, out.settle_frames, coarse_end);
  if (!views) return tl::unexpected(views.error());
  done += static_cast<int>(cameras);
  hooks.progress({0.95, "solving", done});
  auto plane = tagFramePlane(plan, *views);
  if (!plane && plane.error().code == ErrorCode::kDegenerate) {
    // The corners disagree with the coarse pass's verdict (relief finer than its blocks):
    // the cheap step failed its check and the full scan decides.
    out.coarse["planar"] = false;
    out.coarse["then"] = "the full scan: " + plane.error().message;
    return fullScanAfter(plan, hooks, std::move(out), 0.95, done);
  }
  if (!plane) return calibrationFailed("the wall's plane: " + plane.error().message);
  auto solved = solveTagFrame(plan, *views, plane->fit.plane, out);
  if (!solved) return tl::unexpected(solved.error());
  if (plan.scene_plane) *plan.scene_plane = plane->fit.plane;
  out.triangulated_plane = std::move(plane->fit);
  return out;
}

}  // namespace procam::daemon
