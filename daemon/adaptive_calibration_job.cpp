// The calibrate operation's adaptive path ("mode": "adaptive"): skip what the scene does
// not need ([Raskar02] §4.1.4 starts from a coarse 16x12 binary-coded pass). The coarse
// Gray pass tells, from one camera, whether the surface is planar (a plane seen through
// the projector is one homography, §3.2.5); on a plane one AprilTag frame then gives the
// collineation route (b′) needs (tag_calibration_job.cpp), 19 frames in all where the
// full scan shows 50; a surface that is not planar is refused, as route (b′) would
// calibrate it wrongly. On a worker; never touches daemon state.
#include <opencv2/imgproc.hpp>

#include "calibration_job.hpp"
#include "protocol.hpp"
#include "structured_light/adaptive_scan.hpp"
#include "structured_light/decoder.hpp"

namespace procam::daemon {

namespace code = proto::code;

tl::expected<CalibrationOutcome, CalibrationFailure> runAdaptiveCalibration(
    const CalibrationPlan& plan, const CalibrationHooks& hooks) {
  const CalibrationFailure cancelled{code::kCancelled, "calibration cancelled"};
  const auto failed = [&](const std::string& why) {
    return tl::unexpected(CalibrationFailure{code::kFailed, why});
  };
  if (!plan.coarse || !plan.tags || !plan.plane || plan.cameras.empty()) {
    return failed("internal: the adaptive path is route (b′) with a camera and a plane");
  }
  const sl::PatternSet& coarse = *plan.coarse;
  const CalibrationCamera& cam = plan.cameras.front();
  CalibrationOutcome out;
  auto settled = settleFor(plan, hooks, out);
  if (!settled) return tl::unexpected(settled.error());
  const double start = *settled;
  // The coarse pass takes this share of the progress; the tag frame the rest.
  const double coarse_end = start + (0.9 - start) * 0.9;
  std::vector<cv::Mat> captures;
  for (std::size_t f = 0; f < coarse.frames.size(); ++f) {
    if (hooks.cancelled()) return tl::unexpected(cancelled);
    cv::Mat rgb;
    cv::cvtColor(sl::renderFrame(coarse, f), rgb, cv::COLOR_GRAY2RGB);
    auto shown = showAndSettle(plan, rgb, "show a coarse pattern", out.settle_frames, hooks);
    if (!shown) return tl::unexpected(shown.error());
    if (!*shown) return tl::unexpected(cancelled);
    auto grey = captureGray(cam.device);
    if (!grey) return tl::unexpected(grey.error());
    captures.push_back(std::move(*grey));
    const int done = static_cast<int>(f + 1);
    hooks.progress(
        {start + (coarse_end - start) * done / double(coarse.frames.size()), "capturing", done});
  }
  auto decoded = sl::decode(coarse, captures);
  if (!decoded) return failed("camera '" + cam.device.name + "': " + decoded.error().message);
  sl::AdaptiveOptions options;
  options.full.width = coarse.options.width;
  options.full.height = coarse.options.height;
  // Lens distortion bends a plane's image off one homography: the blocks are tested in
  // ideal pixels.
  options.undistort = [&model = cam.model](const Vec2& px) {
    auto ideal = model.undistortPixel(px);
    return ideal ? *ideal : px;
  };
  auto test = sl::testPlanarity(coarse, *decoded, options);
  if (!test) {
    return failed("the coarse pass: camera '" + cam.device.name + "': " + test.error().message);
  }
  out.coarse = {{"frames", static_cast<int>(coarse.frames.size())},
                {"planar", test->planar},
                {"blocks", test->camera.size()},
                {"rms_px", test->rms_px},
                {"tolerance_px", test->tolerance_px}};
  if (!test->planar) {
    return failed(
        "the coarse pass finds the surface not planar (its " + std::to_string(test->camera.size()) +
        " blocks fit one homography to " + std::to_string(test->rms_px) +
        " projector px RMS, over the " + std::to_string(test->tolerance_px) +
        " px a plane allows): route (b′) needs a plane; calibrate with two cameras (route (a))");
  }
  return tagFrameOutcome(plan, hooks, std::move(out), coarse_end);
}

}  // namespace procam::daemon
