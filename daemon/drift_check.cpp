#include "drift_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <thread>
#include <vector>

#include "drift/fiducial_misregistration.hpp"
#include "drift/reference_blur.hpp"
#include "drift/shown_light.hpp"
#include "protocol.hpp"
#include "render/cpu_renderer.hpp"
#include "render/post_render_warp.hpp"

namespace procam::daemon {

namespace code = proto::code;

namespace {

// Half the framebuffer's resolution: a camera seeing a wall-sized image has fewer pixels
// than the projector, so the full grid adds work and no information.
constexpr int kGridFactor = 2;
constexpr double kMinSeenShare = 0.1;

// Where the framebuffer lights the display surface by the rig model: the plane's
// collineation, or the projector's pixel rays through its post-rendering warp meeting the
// mesh, the frame drawn by the lookup warp or two-pass path having gone through the same.
Result<void> litSurface(const DriftCheckPlan& plan, DriftReference& ref) {
  if (!plan.surface_mesh) {
    ref.lit = drift::planeLitSurface(plan.projector_to_plane, plan.framebuffer);
    return {};
  }
  auto warp = render::projectorPostRenderWarp(plan.projector_model,
                                              plan.own_mesh ? &plan.surface_mesh->mesh() : nullptr);
  if (!warp) return fail(warp.error().code, "post-rendering warp: " + warp.error().message);
  std::shared_ptr<const render::WarpGrid> grid;
  if (*warp) grid = std::shared_ptr<const render::WarpGrid>(*warp, &(*warp)->grid);
  auto rays = render::pixelRays(plan.projector_model.projectionMatrix(), grid);
  if (!rays) return tl::unexpected(rays.error());
  ref.rays = std::make_shared<const render::PixelRays>(std::move(*rays));
  ref.lit.occluder = plan.surface_mesh;
  ref.lit.point = [rays = ref.rays, mesh = plan.surface_mesh](const Vec2& fb) {
    auto hit = mesh->intersect(rays->through(fb.x(), fb.y()));
    return hit ? std::optional<Vec3>(hit->point) : std::nullopt;
  };
  if (grid) ref.lit.to_pinhole = [rays = ref.rays](const Vec2& fb) { return rays->toPinhole(fb); };
  return {};
}

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
  // The frame's light as the camera sees it (wall_oblique: the tiles scatter 0.11 px at
  // rest where code values gave 0.18).
  auto shown = drift::shownLight(cpu.frame(), plan.projector_gamma, ref->grid);
  if (!shown) return failed(shown.error().message);
  ref->shown = std::move(*shown);
  if (!plan.setup->final_stage.alpha.empty()) {
    // Only where this projector alone lights the wall: the camera sees the sum of the
    // projectors in a blended overlap, the reference only this one's share.
    cv::Mat full = plan.setup->final_stage.alpha == 255;
    cv::erode(full, full, cv::Mat(), cv::Point(-1, -1), kGridFactor);
    cv::resize(full, ref->usable, ref->grid.size(), 0, 0, cv::INTER_NEAREST);
  }
  if (auto lit = litSurface(plan, *ref); !lit) return failed(lit.error().message);
  auto map = drift::projectorCameraMap(ref->lit, plan.camera_model, ref->grid);
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

// The camera's frame against the reference, blurred as the plan's view sees it, or as a
// fit over the candidates finds it when the view has none yet.
Result<drift::Misregistration> measured(const DriftCheckPlan& plan, const DriftReference& ref,
                                        const cv::Mat& frame, DriftCheck& out) {
  drift::MisregistrationOptions options;
  if (plan.reference_blur) {
    options.reference_blur_px = *plan.reference_blur;
    return drift::measureMisregistration(ref.shown, frame, ref.map, ref.grid, options, ref.usable);
  }
  auto fit = drift::fitReferenceBlur(ref.shown, frame, ref.map, ref.grid, options, ref.usable);
  if (!fit) return tl::unexpected(fit.error());
  out.blur_fitted = true;
  out.fitted_blur = fit->sigma_px;
  return std::move(fit->at_best);
}

}  // namespace

bool referenceFits(const DriftCheckPlan& plan) {
  const auto& r = plan.reference;
  return r && r->setup == plan.setup && r->image == plan.image &&
         r->rig_generation == plan.rig_generation && r->camera == plan.camera.name;
}

namespace {

// `frames` of the camera, averaged (CV_32F).
tl::expected<cv::Mat, CalibrationFailure> captureMean(const DriftCheckPlan& plan) {
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
  return sum;
}

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// The check's reference, made again when it does not fit (a fiducial check makes it too:
// the corrections read the camera's map from it).
tl::expected<void, CalibrationFailure> reference(const DriftCheckPlan& plan, DriftCheck& out,
                                                 Clock::time_point start) {
  if (referenceFits(plan)) {
    out.reference = plan.reference;
    return {};
  }
  auto ref = makeReference(plan);
  if (!ref) return tl::unexpected(ref.error());
  out.reference = *ref;
  out.reference_s = since(start);
  return {};
}

// Where the content's light on the work grid is plain over a tag's width around each
// pixel: its standard deviation under the drift check's texture floor. In a blended
// overlap the reference holds this projector's share only; the content there is that
// share over its weight (eq. 4.3 scales the light), where a neighbour draws it at full
// weight. Where the weight is 0 nothing tells: not plain.
cv::Mat plainContent(const DriftReference& ref, const render::FinalStage& stage, int tag_work_px) {
  const double floor = drift::MisregistrationOptions{}.min_texture;
  cv::Mat content = ref.shown.clone();
  cv::Mat weighted;  // where the frame is weighted at all
  if (!stage.alpha.empty()) {
    cv::Mat weight;
    cv::resize(stage.alpha, weight, ref.grid.size(), 0, 0, cv::INTER_AREA);
    weight.convertTo(weight, CV_32F, 1.0 / 255);
    weighted = weight > 0;
    cv::divide(content, cv::max(weight, 1.0 / 255), content);
  }
  const cv::Size window(std::max(3, tag_work_px), std::max(3, tag_work_px));
  cv::Mat mean, sq, mean_sq;
  cv::blur(content, mean, window);
  cv::multiply(content, content, sq);
  cv::blur(sq, mean_sq, window);
  cv::Mat plain = (mean_sq - mean.mul(mean)) < floor * floor;
  if (!weighted.empty()) {
    cv::Mat none;
    cv::erode(weighted, none, cv::Mat(), cv::Point(-1, -1), 1);
    cv::bitwise_and(plain, none, plain);
  }
  return plain;
}

tl::expected<DriftCheck, CalibrationFailure> runFiducialCheck(const DriftCheckPlan& plan) {
  const auto start = Clock::now();
  DriftCheck out;
  out.fiducial = true;
  if (auto ok = reference(plan, out, start); !ok) return tl::unexpected(ok.error());
  const FiducialFrame& f = *plan.fiducial;
  const auto failed = [&](const std::string& why) {
    return tl::unexpected(
        CalibrationFailure{code::kFailed, "drift check of output '" + plan.output + "': " + why});
  };
  if (!plan.output_device.device)
    return failed("internal: no output to show the fiducial frame on");
  if (f.rgb.size() != plan.framebuffer) {
    return failed("the fiducial frame is not the framebuffer's size");
  }
  if (auto shown = showFrame(plan.output_device, f.rgb, "show the fiducial frame"); !shown) {
    return tl::unexpected(shown.error());
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(plan.settle_s));
  const auto capture = Clock::now();
  auto mean = captureMean(plan);
  if (!mean) return tl::unexpected(mean.error());
  out.capture_s = since(capture);
  const auto measure = Clock::now();
  auto found = findFiducials(f, *mean);
  if (!found) return failed(found.error());
  // Corners this projector alone lights, and those in a blended overlap where the content
  // is plain over a tag: the neighbour draws the same content there, so its light is
  // smooth and shifts no corner (cylinder3 with the side projectors grey over the tags:
  // 0.11 px at rest), where a textured neighbour's could.
  const DriftReference& ref = *out.reference;
  double tag_px = 0;  // a tag's side, framebuffer pixels
  if (!f.grid.tags.empty()) {
    const auto& c = f.grid.tags.front().corners;
    tag_px = (c[1] - c[0]).norm();
  }
  const cv::Mat plain = plainContent(ref, ref.setup->final_stage,
                                     static_cast<int>(std::lround(tag_px / ref.grid.factor)));
  const auto counts = [&](const Vec2& drawn) {
    const Vec2 w = ref.grid.toWork(drawn);
    const int x = std::clamp(static_cast<int>(std::lround(w.x())), 0, ref.shown.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(w.y())), 0, ref.shown.rows - 1);
    return ref.usable.empty() || ref.usable.at<uint8_t>(y, x) != 0 || plain.at<uint8_t>(y, x) != 0;
  };
  std::vector<Vec2> shown;
  for (const Vec2& c : f.corners) {
    if (counts(c)) shown.push_back(c);
  }
  std::erase_if(*found, [&](const drift::FiducialCorner& c) { return !counts(c.drawn); });
  // On a plane through the collineation; on a mesh through the reference's map of the
  // framebuffer into the camera, taken back.
  auto m = plan.surface_mesh ? drift::fiducialMisregistration(shown, *found, ref.map, ref.grid)
                             : drift::fiducialMisregistration(
                                   shown, *found, plan.projector_to_plane, plan.camera_model);
  if (!m) return failed(m.error().message);
  out.misregistration = std::move(*m);
  out.measure_s = since(measure);
  out.seconds = since(start);
  return out;
}

}  // namespace

tl::expected<DriftCheck, CalibrationFailure> runDriftCheck(const DriftCheckPlan& plan) {
  if (plan.fiducial) return runFiducialCheck(plan);
  const auto start = Clock::now();
  DriftCheck out;
  if (auto ok = reference(plan, out, start); !ok) return tl::unexpected(ok.error());
  if (plan.hold_until) std::this_thread::sleep_until(*plan.hold_until);
  const auto capture = Clock::now();
  auto sum = captureMean(plan);
  if (!sum) return tl::unexpected(sum.error());
  out.capture_s = since(capture);
  const auto measure = Clock::now();
  auto m = measured(plan, *out.reference, *sum, out);
  out.measure_s = since(measure);
  if (!m) {
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "drift check of output '" + plan.output + "': " + m.error().message});
  }
  out.misregistration = std::move(*m);
  out.seconds = since(start);
  return out;
}

std::vector<tl::expected<DriftCheck, CalibrationFailure>> runDriftChecks(
    const std::vector<DriftCheckPlan>& plans) {
  std::vector<tl::expected<DriftCheck, CalibrationFailure>> out;
  if (plans.size() == 1 || (!plans.empty() && plans[0].fiducial)) {
    out.push_back(runDriftCheck(plans[0]));
    return out;
  }
  const auto start = Clock::now();
  std::vector<DriftCheck> checks(plans.size());
  std::vector<std::optional<CalibrationFailure>> failed(plans.size());
  for (std::size_t i = 0; i < plans.size(); ++i) {
    if (auto ok = reference(plans[i], checks[i], Clock::now()); !ok) failed[i] = ok.error();
  }
  const auto capture = Clock::now();
  auto mean = captureMean(plans[0]);
  const double capture_s = since(capture);
  for (std::size_t i = 0; i < plans.size(); ++i) {
    if (!mean) failed[i] = mean.error();
    if (failed[i]) {
      out.push_back(tl::unexpected(*failed[i]));
      continue;
    }
    DriftCheck& c = checks[i];
    c.capture_s = capture_s;
    const auto measure = Clock::now();
    auto m = measured(plans[i], *c.reference, *mean, c);
    c.measure_s = since(measure);
    if (!m) {
      out.push_back(tl::unexpected(CalibrationFailure{
          code::kFailed, "drift check of output '" + plans[i].output + "': " + m.error().message}));
      continue;
    }
    c.misregistration = std::move(*m);
    c.seconds = since(start);
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace procam::daemon
