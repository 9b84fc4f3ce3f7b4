#include "drift_check.hpp"

#include <chrono>
#include <opencv2/imgproc.hpp>

#include "protocol.hpp"
#include "render/cpu_renderer.hpp"

namespace procam::daemon {

namespace code = proto::code;

namespace {

// Half the framebuffer's resolution: a camera seeing a wall-sized image has fewer pixels
// than the projector, so the full grid adds work and no information.
constexpr int kGridFactor = 2;
constexpr double kMinSeenShare = 0.1;

tl::expected<std::shared_ptr<const DriftReference>, CalibrationFailure> makeReference(
    const DriftCheckPlan& plan) {
  const auto failed = [&](const std::string& why) {
    return tl::unexpected(
        CalibrationFailure{code::kFailed, "drift check of output '" + plan.output + "': " + why});
  };
  if (!plan.setup || !plan.image) return failed("no frame to compare with");
  render::CpuRenderer cpu;
  if (auto ok = cpu.configure(*plan.setup); !ok) return failed(ok.error().message);
  if (auto drawn = cpu.render(render::Content(plan.image.get(), nullptr, 1)); !drawn) {
    return failed(drawn.error().message);
  }
  if (cpu.frame().size() != plan.framebuffer) {
    return failed("the output shows " + std::to_string(cpu.frame().cols) + "x" +
                  std::to_string(cpu.frame().rows) + " frames; the rig model calibrated " +
                  std::to_string(plan.framebuffer.width) + "x" +
                  std::to_string(plan.framebuffer.height));
  }
  auto ref = std::make_shared<DriftReference>();
  ref->setup = plan.setup;
  ref->image = plan.image;
  ref->rig_generation = plan.rig_generation;
  ref->camera = plan.camera.name;
  ref->grid = {cpu.frame().size(), kGridFactor};
  cv::Mat grey, f;
  cv::cvtColor(cpu.frame(), grey, cv::COLOR_RGBA2GRAY);
  grey.convertTo(f, CV_32F);
  cv::resize(f, ref->shown, ref->grid.size(), 0, 0, cv::INTER_AREA);
  if (!plan.setup->final_stage.alpha.empty()) {
    // Only where this projector alone lights the wall: the camera sees the sum of the
    // projectors in a blended overlap, the reference only this one's share.
    cv::Mat full = plan.setup->final_stage.alpha == 255;
    cv::erode(full, full, cv::Mat(), cv::Point(-1, -1), kGridFactor);
    cv::resize(full, ref->usable, ref->grid.size(), 0, 0, cv::INTER_NEAREST);
  }
  auto map = drift::projectorCameraMap(plan.projector_to_plane, plan.camera_model, ref->grid);
  if (!map) return failed(map.error().message);
  ref->map = std::move(*map);
  cv::Mat x;
  cv::extractChannel(ref->map, x, 0);
  ref->seen_share = cv::countNonZero(x >= 0) / static_cast<double>(x.total());
  if (ref->seen_share < kMinSeenShare) {
    return failed("camera '" + plan.camera.name + "' sees " +
                  std::to_string(static_cast<int>(100 * ref->seen_share)) +
                  " % of the frame by the rig model (at least 10 % needed)");
  }
  return ref;
}

}  // namespace

bool referenceFits(const DriftCheckPlan& plan) {
  const auto& r = plan.reference;
  return r && r->setup == plan.setup && r->image == plan.image &&
         r->rig_generation == plan.rig_generation && r->camera == plan.camera.name;
}

tl::expected<DriftCheck, CalibrationFailure> runDriftCheck(const DriftCheckPlan& plan) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  const auto start = Clock::now();
  DriftCheck out;
  if (referenceFits(plan)) {
    out.reference = plan.reference;
  } else {
    auto ref = makeReference(plan);
    if (!ref) return tl::unexpected(ref.error());
    out.reference = *ref;
    out.reference_s = since(start);
  }
  const auto capture = Clock::now();
  plan.fence.wait();
  cv::Mat sum;
  for (int i = 0; i < std::max(1, plan.frames); ++i) {
    auto grey = captureGray(plan.camera);
    if (!grey) return tl::unexpected(grey.error());
    if (grey->cols != plan.camera_model.width || grey->rows != plan.camera_model.height) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "camera '" + plan.camera.name + "' gives " + std::to_string(grey->cols) +
                             "x" + std::to_string(grey->rows) + " frames; the rig model has it " +
                             std::to_string(plan.camera_model.width) + "x" +
                             std::to_string(plan.camera_model.height)});
    }
    if (sum.empty()) sum = cv::Mat::zeros(grey->size(), CV_32F);
    cv::accumulate(*grey, sum);
  }
  sum /= std::max(1, plan.frames);
  out.capture_s = since(capture);
  const auto measure = Clock::now();
  const DriftReference& ref = *out.reference;
  auto m = drift::measureMisregistration(ref.shown, sum, ref.map, ref.grid, {}, ref.usable);
  out.measure_s = since(measure);
  if (!m) {
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "drift check of output '" + plan.output + "': " + m.error().message});
  }
  out.misregistration = std::move(*m);
  out.seconds = since(start);
  return out;
}

}  // namespace procam::daemon
