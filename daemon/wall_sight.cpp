#include "wall_sight.hpp"

#include <chrono>
#include <opencv2/imgproc.hpp>

#include "output_frames.hpp"
#include "protocol.hpp"

namespace procam::daemon {

namespace code = proto::code;

tl::expected<WallSight, CalibrationFailure> measureWallSight(const WallSightPlan& plan) {
  const CalibrationFailure stopped{code::kCancelled, "stopped: the projector moved"};
  auto halted = [&] { return plan.stop && plan.stop->load(); };
  if (!plan.grid || plan.frames < 1) {
    return tl::unexpected(CalibrationFailure{code::kInternal, "wall sight: no dot grid"});
  }
  if (halted()) return tl::unexpected(stopped);
  const auto start = std::chrono::steady_clock::now();
  cv::Mat rgb;
  cv::cvtColor(plan.grid->image, rgb, cv::COLOR_GRAY2RGB);
  procam_image frame = rgbImage(rgb);
  char err[256] = {0};
  const auto& out = plan.output.device->raw();
  if (int rc = out.ops.output->show(out.self, &frame, err, sizeof err - 1); rc != PROCAM_OK) {
    return tl::unexpected(deviceFailure("output", plan.output.name, rc, "show the dot grid", err));
  }
  const CalibrationHooks hooks{halted, {}};
  if (!waitCancellable(plan.settle_s, hooks)) return tl::unexpected(stopped);
  cv::Mat sum;
  double full_scale = 255;
  for (int i = 0; i < plan.frames; ++i) {
    if (halted()) return tl::unexpected(stopped);
    auto grey = captureGray(plan.camera);
    if (!grey) return tl::unexpected(grey.error());
    if (grey->cols != plan.camera_in_projector.width ||
        grey->rows != plan.camera_in_projector.height) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "camera '" + plan.camera.name + "' gives " + std::to_string(grey->cols) +
                             "x" + std::to_string(grey->rows) + " frames; the rig model has it " +
                             std::to_string(plan.camera_in_projector.width) + "x" +
                             std::to_string(plan.camera_in_projector.height)});
    }
    full_scale = grey->depth() == CV_16U ? 65535.0 : 255.0;
    if (sum.empty()) sum = cv::Mat::zeros(grey->size(), CV_32F);
    cv::accumulate(*grey, sum);
  }
  WallSight out_sight;
  out_sight.frames = plan.frames;
  out_sight.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sum /= plan.frames;
  keystone::WallFromDotsOptions options;
  options.detect.full_scale = full_scale;
  auto wall =
      keystone::wallFromDots(*plan.grid, sum, plan.projector, plan.camera_in_projector, options);
  if (!wall) {
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "camera '" + plan.camera.name + "': " + wall.error().message});
  }
  out_sight.wall = *wall;
  return out_sight;
}

}  // namespace procam::daemon
