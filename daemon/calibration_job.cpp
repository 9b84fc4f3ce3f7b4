#include "calibration_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <span>
#include <thread>

#include "calibration/wall_views_route.hpp"
#include "device_set.hpp"
#include "latency_probe.hpp"
#include "output_frames.hpp"
#include "protocol.hpp"
#include "structured_light/decoder.hpp"

namespace procam::daemon {

namespace code = proto::code;

tl::unexpected<CalibrationFailure> calibrationFailed(const std::string& why) {
  return tl::unexpected(CalibrationFailure{code::kFailed, why});
}

CalibrationFailure deviceFailure(const char* family, const std::string& name, int rc,
                                 const char* what, const char* reason) {
  const std::string why = reason[0] ? reason : "no reason given";
  if (closesDevice(rc)) {
    return {code::kCancelled,
            "calibration cancelled: " + std::string(family) + " '" + name + "' " +
                (rc == PROCAM_EEND ? "ended" : "is gone") + " (" + why + ")",
            name, rc};
  }
  return {code::kIo, std::string(family) + " '" + name + "' failed to " + what + ": " + why, name,
          rc};
}

cv::Mat grayImage(const procam_image& img) {
  const int w = static_cast<int>(img.width), h = static_cast<int>(img.height);
  switch (img.format) {
    case PROCAM_PIXEL_GRAY8:
      return cv::Mat(h, w, CV_8UC1, img.data, img.stride).clone();
    case PROCAM_PIXEL_GRAY16:
      return cv::Mat(h, w, CV_16UC1, img.data, img.stride).clone();
    case PROCAM_PIXEL_RGB8: {
      cv::Mat gray;
      cv::cvtColor(cv::Mat(h, w, CV_8UC3, img.data, img.stride), gray, cv::COLOR_RGB2GRAY);
      return gray;
    }
    case PROCAM_PIXEL_RGBA8: {
      cv::Mat gray;
      cv::cvtColor(cv::Mat(h, w, CV_8UC4, img.data, img.stride), gray, cv::COLOR_RGBA2GRAY);
      return gray;
    }
  }
  return {};
}

tl::expected<void, CalibrationFailure> showFrame(const CalibrationDevice& output,
                                                 const cv::Mat& rgb, const char* what) {
  procam_image frame = rgbImage(rgb);
  char err[256] = {0};
  const auto& raw = output.device->raw();
  if (int rc = raw.ops.output->show(raw.self, &frame, err, sizeof err - 1); rc != PROCAM_OK) {
    return tl::unexpected(deviceFailure("output", output.name, rc, what, err));
  }
  return {};
}

bool waitCancellable(double seconds, const CalibrationHooks& hooks) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (hooks.cancelled()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return !hooks.cancelled();
}

tl::expected<cv::Mat, CalibrationFailure> captureGray(const CalibrationDevice& cam) {
  const auto& raw = cam.device->raw();
  procam_image img{};
  char err[256] = {0};
  if (int rc = raw.ops.camera->capture(raw.self, 5000, &img, err, sizeof err - 1);
      rc != PROCAM_OK) {
    return tl::unexpected(deviceFailure("camera", cam.name, rc, "capture", err));
  }
  cv::Mat gray = grayImage(img);
  if (gray.empty()) {
    return tl::unexpected(CalibrationFailure{
        code::kIo, "camera '" + cam.name + "' returned an unknown pixel format"});
  }
  return gray;
}

// Shows `rgb` on the plan's output and waits `settle_frames` refreshes for it to reach
// the screen ([Raskar02] §4.1.1 assumes a static projected image per capture); false
// when cancelled meanwhile.
tl::expected<bool, CalibrationFailure> showAndSettle(const CalibrationPlan& plan,
                                                     const cv::Mat& rgb, const char* what,
                                                     int settle_frames,
                                                     const CalibrationHooks& hooks) {
  if (auto shown = showFrame(plan.output, rgb, what); !shown) return tl::unexpected(shown.error());
  return waitCancellable(settle_frames / plan.refresh_hz, hooks);
}

namespace {

// The display plane from the board on it, as the camera saw it while the projector
// showed white (the board is lit by the projector alone in a dark room).
tl::expected<calib::BoardPlane, CalibrationFailure> planeOfBoard(const CalibrationPlan& plan,
                                                                 const cv::Mat& white) {
  const CalibrationCamera& cam = plan.cameras.at(0);
  auto view = calib::detectBoard(*plan.board, white);
  if (!view) {
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "camera '" + cam.device.name + "' does not see the board " +
                           plan.board_text +
                           " on the display plane in the white frame: " + view.error().message});
  }
  auto plane = calib::boardPlane(cam.model, *view);
  if (!plane) {
    return tl::unexpected(CalibrationFailure{
        code::kFailed, "the board " + plan.board_text + " seen by camera '" + cam.device.name +
                           "' gives no display plane: " + plane.error().message});
  }
  return *plane;
}

// The camera's mean at each ramp level over the pixels that decoded this projector
// (flags 0), eroded by 3 pixels so that its blurred edge does not count; and, from the
// same pixels' white minus black, the projector's brightness across its frame.
Result<blend::ProjectorResponse> rampResponse(const std::vector<cv::Mat>& ramp,
                                              const sl::Decoded& decoded, cv::Size framebuffer,
                                              std::string& brightness_note) {
  cv::Mat mask = decoded.flags == 0;
  cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(7, 7)));
  if (cv::countNonZero(mask) < 100) {
    return fail(ErrorCode::kTooFewPoints, "fewer than 100 camera pixels see the projector");
  }
  std::vector<blend::RampSample> samples;
  for (std::size_t i = 0; i < ramp.size(); ++i) {
    if (ramp[i].size() != mask.size()) {
      return fail(ErrorCode::kInvalidInput, "the ramp's captures changed size");
    }
    samples.push_back({CalibrationPlan::kRampLevels[i], cv::mean(ramp[i], mask)[0]});
  }
  auto response = blend::fitResponse(samples);
  if (!response) return response;
  // Without its brightness across the frame the response still serves (a gain per
  // projector instead of matching per pixel); the reply says why.
  auto brightness =
      blend::measureBrightness(ramp.back(), ramp.front(), decoded.u, decoded.v, mask, framebuffer);
  if (brightness) {
    response->brightness = std::move(*brightness);
  } else {
    brightness_note = brightness.error().message;
  }
  return response;
}

}  // namespace

tl::expected<void, CalibrationFailure> blankOutput(const CalibrationPlan& plan) {
  const cv::Mat black(plan.set.options.height, plan.set.options.width, CV_8UC3, cv::Scalar::all(0));
  const CalibrationHooks no_cancel{[] { return false; }, {}};
  auto shown = showAndSettle(plan, black, "show black", 0, no_cancel);
  if (!shown) return tl::unexpected(shown.error());
  return {};
}

tl::expected<void, CalibrationFailure> blankOutput(const IdleOutput& idle) {
  const cv::Mat black(idle.height, idle.width, CV_8UC3, cv::Scalar::all(0));
  return showFrame(idle.output, black, "show black");
}

namespace {

// Shows `rgb` on every member's output, then waits `settle_frames` refreshes once.
tl::expected<bool, CalibrationFailure> showAllAndSettle(
    std::span<const CalibrationPlan* const> members, const cv::Mat& rgb, const char* what,
    int settle_frames, const CalibrationHooks& hooks) {
  for (std::size_t m = 0; m + 1 < members.size(); ++m) {
    auto shown = showAndSettle(*members[m], rgb, what, 0, hooks);
    if (!shown) return shown;
  }
  return showAndSettle(*members.back(), rgb, what, settle_frames, hooks);
}

// The decoded map of one member of a batch: only where its footprint lies (other
// pixels flagged as shadow: another member's light).
sl::Decoded maskedToFootprint(const sl::Decoded& d, const cv::Mat& footprint) {
  if (footprint.empty()) return d;
  sl::Decoded out = d;
  out.u = d.u.clone();
  out.v = d.v.clone();
  out.confidence = d.confidence.clone();
  out.flags = d.flags.clone();
  const cv::Mat outside = footprint == 0;
  out.flags.setTo(sl::kShadow, outside);
  out.u.setTo(-1.0f, outside);
  out.v.setTo(-1.0f, outside);
  out.confidence.setTo(0.0f, outside);
  out.decoded = cv::countNonZero(out.flags == 0);
  return out;
}

}  // namespace

tl::expected<CalibrationOutcome, CalibrationFailure> runCalibration(const CalibrationPlan& plan,
                                                                    const CalibrationHooks& hooks) {
  const CalibrationPlan* one[] = {&plan};
  auto outcomes = runBatchCalibration(one, {}, hooks);
  if (!outcomes) return tl::unexpected(outcomes.error());
  return std::move(outcomes->front());
}

tl::expected<double, CalibrationFailure> settleFor(const CalibrationPlan& plan,
                                                   const CalibrationHooks& hooks,
                                                   CalibrationOutcome& outcome) {
  outcome.settle_frames = plan.settle_frames;
  if (!plan.auto_settle) return 0.0;
  // Settle by the measured display-to-capture latency of these cameras.
  LatencyPlan probe{plan.output,
                    static_cast<uint32_t>(plan.set.options.width),
                    static_cast<uint32_t>(plan.set.options.height),
                    plan.refresh_hz,
                    {},
                    plan.latency.latency_repeats,
                    plan.latency.latency_timeout_s,
                    plan.latency.margin_frames};
  for (const auto& c : plan.cameras) probe.cameras.push_back(c.device);
  CalibrationHooks probe_hooks{hooks.cancelled, [&](const CalibrationProgress& p) {
                                 hooks.progress({0.1 * p.fraction, "latency", 0});
                               }};
  auto measured = runLatencyProbe(probe, probe_hooks);
  if (!measured) return tl::unexpected(measured.error());
  outcome.settle_frames = measured->settle_frames;
  outcome.latency = latencyJson(*measured, probe);
  return 0.1;
}

tl::expected<std::vector<CalibrationOutcome>, CalibrationFailure> runBatchCalibration(
    std::span<const CalibrationPlan* const> members,
    const std::vector<std::vector<cv::Mat>>& footprints, const CalibrationHooks& hooks) {
  const CalibrationFailure cancelled{code::kCancelled, "calibration cancelled"};
  if (members.empty() || (!footprints.empty() && footprints.size() != members.size()) ||
      (members.size() > 1 && footprints.empty())) {
    return tl::unexpected(CalibrationFailure{code::kFailed,
                                             "internal: a scan batch without "
                                             "its members' footprints"});
  }
  const CalibrationPlan& plan = *members.front();
  if (plan.tags) {
    if (members.size() > 1) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "internal: a tag frame calibrates one projector at a time"});
    }
    auto one = plan.coarse ? runAdaptiveCalibration(plan, hooks) : runTagCalibration(plan, hooks);
    if (!one) return tl::unexpected(one.error());
    std::vector<CalibrationOutcome> outcomes;
    outcomes.push_back(std::move(*one));
    return outcomes;
  }
  for (const CalibrationPlan* m : members) {
    if (members.size() > 1 && m->board) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "internal: a board's plane is found with one projector at a time"});
    }
  }
  const int total = plan.captures();
  std::vector<CalibrationOutcome> outcomes(members.size());
  CalibrationOutcome& outcome = outcomes.front();
  auto settled = settleFor(plan, hooks, outcome);
  if (!settled) return tl::unexpected(settled.error());
  const double start = *settled;  // progress fraction where the captures start
  std::vector<std::vector<cv::Mat>> captures(plan.cameras.size());
  int done = 0;
  for (std::size_t f = 0; f < plan.set.frames.size(); ++f) {
    if (hooks.cancelled()) return tl::unexpected(cancelled);
    cv::Mat rgb;
    cv::cvtColor(sl::renderFrame(plan.set, f), rgb, cv::COLOR_GRAY2RGB);
    auto shown = showAllAndSettle(members, rgb, "show a pattern", outcome.settle_frames, hooks);
    if (!shown) return tl::unexpected(shown.error());
    if (!*shown) return tl::unexpected(cancelled);
    for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
      auto gray = captureGray(plan.cameras[c].device);
      if (!gray) return tl::unexpected(gray.error());
      captures[c].push_back(std::move(*gray));
      ++done;
      hooks.progress({start + (0.9 - start) * done / total, "capturing", done});
      if (hooks.cancelled()) return tl::unexpected(cancelled);
    }
    // The board is looked for as soon as it is lit: a board the camera does not see
    // ends the run before the rest of the sequence is shown.
    if (plan.board && plan.set.frames[f].kind == sl::FrameKind::kWhite && !outcome.board) {
      auto found = planeOfBoard(plan, captures[0].back());
      if (!found) return tl::unexpected(found.error());
      outcome.board = *found;
    }
  }
  // The response ramp: grey levels on the whole frame, seen by the first camera.
  std::vector<cv::Mat> ramp;
  for (int level : plan.response ? std::span<const int>(CalibrationPlan::kRampLevels)
                                 : std::span<const int>()) {
    if (hooks.cancelled()) return tl::unexpected(cancelled);
    const cv::Mat grey(plan.set.options.height, plan.set.options.width, CV_8UC3,
                       cv::Scalar::all(level));
    auto shown = showAllAndSettle(members, grey, "show a grey", outcome.settle_frames, hooks);
    if (!shown) return tl::unexpected(shown.error());
    if (!*shown) return tl::unexpected(cancelled);
    auto gray = captureGray(plan.cameras[0].device);
    if (!gray) return tl::unexpected(gray.error());
    ramp.push_back(std::move(*gray));
    ++done;
    hooks.progress({start + (0.9 - start) * done / total, "capturing", done});
  }
  std::vector<sl::Decoded> decoded;  // per camera, the whole batch
  for (std::size_t c = 0; c < plan.cameras.size(); ++c) {
    hooks.progress({0.9 + 0.05 * c / plan.cameras.size(), "decoding", total});
    auto d = sl::decode(plan.set, captures[c]);
    if (!d) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "camera '" + plan.cameras[c].device.name + "': " + d.error().message});
    }
    decoded.push_back(std::move(*d));
    if (hooks.cancelled()) return tl::unexpected(cancelled);
  }
  hooks.progress({0.95, "solving", total});
  for (std::size_t m = 0; m < members.size(); ++m) {
    const CalibrationPlan& member = *members[m];
    CalibrationOutcome& out = outcomes[m];
    if (m > 0) {
      out.settle_frames = outcome.settle_frames;
      out.latency = outcome.latency;
    }
    std::vector<calib::DecodedView> views;
    // Cameras at several positions: each sees only some projectors, so a camera that
    // decoded none of this one is no failure; the run's projectors are solved together
    // once all are scanned (solveWallViews).
    const bool wall_views = member.wallViews();
    for (std::size_t c = 0; c < member.cameras.size(); ++c) {
      sl::Decoded d =
          maskedToFootprint(decoded[c], footprints.empty() ? cv::Mat() : footprints[m][c]);
      if (d.decoded == 0 && !wall_views) {
        return tl::unexpected(CalibrationFailure{
            code::kFailed, "camera '" + member.cameras[c].device.name +
                               "' decoded no pixel of output '" + member.output.name +
                               "': it does not see the projected patterns"});
      }
      out.decoded.push_back(d.decoded);
      if (c == 0 && !ramp.empty()) {
        auto response =
            rampResponse(ramp, d, cv::Size(member.set.options.width, member.set.options.height),
                         out.brightness_note);
        // Responses are compared within one camera's exposure: with several cameras
        // only the reference camera measures them, and a projector it sees too little
        // of is left unmeasured (the reply has no response for it).
        if (response) {
          out.response = *response;
        } else if (wall_views) {
          out.response_note = "not measured: camera '" + member.cameras[0].device.name +
                              "' sees too little of it (" + response.error().message + ")";
        } else {
          return tl::unexpected(CalibrationFailure{
              code::kFailed, "the response of output '" + member.output.name +
                                 "' seen by camera '" + member.cameras[0].device.name +
                                 "': " + response.error().message});
        }
      }
      views.push_back({member.cameras[c].device.name, member.cameras[c].model, std::move(d)});
    }
    if (member.known_projector) {
      auto nodes = views.size() > 1
                       ? calib::triangulateNodes(member.set, views[0], views[1], member.grid)
                       : calib::triangulateWithProjector(member.set, *member.known_projector,
                                                         views[0], member.grid);
      auto fit = nodes ? calib::triangulatedPlane(*nodes)
                       : Result<geom::PlaneFit>(tl::unexpected(nodes.error()));
      if (!fit) {
        return tl::unexpected(
            CalibrationFailure{code::kFailed, "the wall's plane: " + fit.error().message});
      }
      out.triangulated_plane = std::move(*fit);
      continue;
    }
    if (wall_views) {
      for (const calib::DecodedView& view : views) {
        auto seen = calib::wallSighting(member.set, view, {.step = member.grid});
        if (!seen) return tl::unexpected(CalibrationFailure{code::kFailed, seen.error().message});
        out.wall_nodes.push_back(std::move(seen->nodes));
      }
      continue;
    }
    if (member.planar()) {
      if (member.board && !outcome.board) {
        return tl::unexpected(
            CalibrationFailure{code::kFailed, "the pattern set has no white frame"});
      }
      if (member.board) out.board = outcome.board;
      const geom::Plane plane = member.board ? out.board->plane : *member.plane;
      auto planar =
          calib::solvePlaneHomographyRoute(member.set, views[0], plane, {.step = member.grid});
      if (!planar) {
        return tl::unexpected(CalibrationFailure{code::kFailed, planar.error().message});
      }
      out.planar = std::move(*planar);
      continue;
    }
    auto nodes = calib::triangulateNodes(member.set, views[0], views[1], member.grid);
    if (!nodes) return tl::unexpected(CalibrationFailure{code::kFailed, nodes.error().message});
    auto route = calib::solveStereoRoute(*nodes);
    if (!route && route.error().code == ErrorCode::kCoplanar) {
      // A planar scene fixes no projection matrix ([Raskar02] §4.1.1 needs relief), but
      // the pair still measures the plane: the projector takes the plane route on it
      // (§4.2.4), as with a plane an installer gives.
      const std::optional<geom::Plane> prior =
          member.scene_plane ? *member.scene_plane : std::optional<geom::Plane>();
      auto fit = calib::triangulatedPlane(*nodes, prior);
      if (!fit) {
        return tl::unexpected(CalibrationFailure{
            code::kFailed, route.error().message + "; as a plane: " + fit.error().message});
      }
      auto planar =
          calib::solvePlaneHomographyRoute(member.set, views[0], fit->plane, {.step = member.grid});
      if (!planar) return tl::unexpected(CalibrationFailure{code::kFailed, planar.error().message});
      out.planar = std::move(*planar);
      if (member.scene_plane) *member.scene_plane = fit->plane;
      out.triangulated_plane = std::move(*fit);
      continue;
    }
    if (!route) return tl::unexpected(CalibrationFailure{code::kFailed, route.error().message});
    out.route = std::move(*route);
  }
  return outcomes;
}

namespace {

// Of every other pixel of every other row, in any single-channel depth.
float percentile(const cv::Mat& image, double q) {
  cv::Mat m;
  image.convertTo(m, CV_32F);
  std::vector<float> v;
  for (int y = 0; y < m.rows; y += 2) {
    const float* r = m.ptr<float>(y);
    for (int x = 0; x < m.cols; x += 2) v.push_back(r[x]);
  }
  if (v.empty()) return 0.0f;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// White minus black in the captures' own depth, saturated at 0 (light is only ever
// compared with a threshold above 0): a run of cameras at several positions keeps one per
// projector and camera until the coarse pass ends.
cv::Mat lightOf(const cv::Mat& white, const cv::Mat& black) {
  cv::Mat diff;
  cv::subtract(white, black, diff);
  return diff;
}

// The camera pixels whose `light` (lightOf) exceeds `threshold`, specks opened away,
// then dilated by 4 pixels for the blur of the light's edge.
cv::Mat litMask(const cv::Mat& light, float threshold) {
  cv::Mat mask = light > threshold;
  const cv::Mat k3 = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, k3);
  cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
  return mask;
}

// Camera pixels a projector lights: its light above 5 % of the light's own 99.5th
// percentile (the projector's light, whatever the exposure: the dim far or grazing parts
// of a curved wall stay in, the camera's noise out). Empty (all zero) when the camera
// sees too little of it: a 99.5th percentile under 5 % of the white view's.
cv::Mat litPixels(const cv::Mat& white, const cv::Mat& light) {
  const float top = percentile(light, 0.995);
  if (!(top > 0.05f * percentile(white, 0.995)) || !(top > 0))
    return cv::Mat(light.size(), CV_8UC1, cv::Scalar(0));
  return litMask(light, 0.05f * top);
}

// Whether two plans can share a batch: the same frames on the same cameras, one route.
bool batchable(const CalibrationPlan& a, const CalibrationPlan& b) {
  if (a.board || b.board || a.tags || b.tags || a.set.frames.size() != b.set.frames.size() ||
      a.set.options.width != b.set.options.width || a.set.options.height != b.set.options.height ||
      a.set.options.mode != b.set.options.mode || a.response != b.response || a.auto_settle ||
      b.auto_settle || a.settle_frames != b.settle_frames || a.cameras.size() != b.cameras.size() ||
      a.planar() != b.planar())
    return false;
  for (std::size_t c = 0; c < a.cameras.size(); ++c) {
    if (a.cameras[c].device.name != b.cameras[c].device.name) return false;
  }
  return true;
}

}  // namespace

bool mayBatch(std::span<const CalibrationPlan* const> plans) {
  for (std::size_t i = 0; i < plans.size(); ++i) {
    for (std::size_t j = i + 1; j < plans.size(); ++j) {
      if (batchable(*plans[i], *plans[j])) return true;
    }
  }
  return false;
}

tl::expected<ScanBatches, CalibrationFailure> planScanBatches(
    std::span<const CalibrationPlan* const> plans, const CalibrationHooks& hooks) {
  const CalibrationFailure cancelled{code::kCancelled, "calibration cancelled"};
  ScanBatches out;
  if (plans.empty()) return out;
  const CalibrationPlan& first = *plans.front();
  const std::size_t cams = first.cameras.size();
  // Every projector of the run shows black already.
  if (!waitCancellable(first.settle_frames / first.refresh_hz, hooks))
    return tl::unexpected(cancelled);
  std::vector<cv::Mat> black;
  for (const auto& cam : first.cameras) {
    auto gray = captureGray(cam.device);
    if (!gray) return tl::unexpected(gray.error());
    black.push_back(std::move(*gray));
  }
  out.footprints.resize(plans.size());
  // Cameras at several positions: each projector's light is kept until the brightest
  // projector's level in every camera is known, and thresholded at 5 % of that level
  // (litPixels' rule would drop a projector's sliver at the edge of a camera's view,
  // under 0.5 % of its pixels, and with it an overlap in that camera).
  const bool shared_level = first.wallViews();
  std::vector<std::vector<cv::Mat>> lights(shared_level ? plans.size() : 0,
                                           std::vector<cv::Mat>(cams));
  std::vector<float> level(cams, 0.0f);
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const CalibrationPlan& p = *plans[i];
    const cv::Mat white(p.set.options.height, p.set.options.width, CV_8UC3, cv::Scalar::all(255));
    auto shown = showAndSettle(p, white, "show white", p.settle_frames, hooks);
    if (!shown) return tl::unexpected(shown.error());
    if (!*shown) return tl::unexpected(cancelled);
    for (std::size_t c = 0; c < cams; ++c) {
      // Plans of other cameras are never batched with these: no footprint for them.
      if (p.cameras.size() != cams || p.cameras[c].device.name != first.cameras[c].device.name) {
        out.footprints[i].emplace_back();
        continue;
      }
      auto gray = captureGray(p.cameras[c].device);
      if (!gray) return tl::unexpected(gray.error());
      if (gray->size() != black[c].size()) {
        out.footprints[i].emplace_back();
        continue;
      }
      cv::Mat light = lightOf(*gray, black[c]);
      if (shared_level) {
        level[c] = std::max(level[c], percentile(light, 0.995));
        lights[i][c] = std::move(light);
        out.footprints[i].emplace_back();  // below, once every level is known
      } else {
        out.footprints[i].push_back(litPixels(*gray, light));
      }
    }
    if (auto ok = blankOutput(p); !ok) return tl::unexpected(ok.error());
    hooks.progress(
        {double(i + 1) / plans.size(), "finding overlaps", static_cast<int>((i + 2) * cams)});
  }
  out.captures = static_cast<int>((plans.size() + 1) * cams);
  for (std::size_t i = 0; shared_level && i < plans.size(); ++i) {
    for (std::size_t c = 0; c < cams; ++c) {
      const cv::Mat& light = lights[i][c];
      if (light.empty()) continue;
      // A camera none of the projectors lights: nothing of this one either.
      out.footprints[i][c] = level[c] > 0 ? litMask(light, 0.05f * level[c])
                                          : cv::Mat(light.size(), CV_8UC1, cv::Scalar(0));
    }
    lights[i].clear();
  }
  // Overlap: the (dilated) lit pixels of two projectors meet in some camera.
  auto overlap = [&](std::size_t i, std::size_t j) {
    for (std::size_t c = 0; c < cams; ++c) {
      const cv::Mat& a = out.footprints[i][c];
      const cv::Mat& b = out.footprints[j][c];
      if (a.empty() || b.empty() || a.size() != b.size()) return true;  // cannot tell
      if (cv::countNonZero(a & b) > 0) return true;
    }
    return false;
  };
  // Seen: every camera sees some of its light (one that does not is scanned alone, and
  // fails or succeeds as it would have); with cameras at several positions, some camera
  // does (each sees only part of the wall).
  std::vector<char> seen(plans.size(), 0);  // once per projector, not per batch tried
  for (std::size_t i = 0; i < plans.size(); ++i) {
    bool any = false, all = !out.footprints[i].empty();
    for (const cv::Mat& m : out.footprints[i]) {
      const bool lit = !m.empty() && cv::countNonZero(m) > 0;
      any = any || lit;
      all = all && lit;
    }
    seen[i] = plans[i]->wallViews() ? any : all;
  }
  for (std::size_t i = 0; i < plans.size(); ++i) {
    // At several positions a projector no camera sees ends the run here, not after
    // every other projector's scan.
    if (plans[i]->wallViews() && !seen[i]) {
      return tl::unexpected(CalibrationFailure{
          code::kFailed, "output '" + plans[i]->output.name +
                             "': none of the cameras sees its light (the coarse pass showed "
                             "it white alone)"});
    }
    bool placed = false;
    for (auto& batch : out.batches) {
      bool fits = seen[i];
      for (std::size_t j : batch) {
        fits = fits && seen[j] && batchable(*plans[i], *plans[j]) && !overlap(i, j);
      }
      if (fits) {
        batch.push_back(i);
        placed = true;
        break;
      }
    }
    if (!placed) out.batches.push_back({i});
  }
  return out;
}

}  // namespace procam::daemon
