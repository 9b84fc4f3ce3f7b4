// The drift check of a fixed rig (recalibrate = "on-drift") on wall_oblique (one 1920x1080
// projector, a fixed 1280x960 camera with 0.8 DN read noise), per content type (a natural
// image's multi-octave noise, text, a smooth gradient):
//  - cost: making the reference (the frame drawn again on the CPU, mapped into the camera),
//    fitting the blur the camera sees it with once (drift::fitReferenceBlur, as the daemon
//    does at a view's first check; every registration below uses it) and one registration
//    (drift::measureMisregistration), against the frame period of a
//    30 fps camera; beside it OpenCV's findTransformECC (homography) registering the same
//    camera view with the frame shown, the library's whole-image alternative, with its
//    error against the true shift;
//  - the noise floor: the misregistration reported at rest over many camera frames (new
//    noise each), whose 99th percentile is the smallest misregistration the check can
//    tell from noise, and the measured against the true shift for small bumps;
//  - a still soak: ten minutes of checks at the daemon's default rate (4 per second, 2
//    frames averaged) at rest on natural content: the largest misregistration seen and
//    whether any run of checks over the 0.5 px threshold lasted the 0.5 s settle time (a
//    false recalibration);
//  - the pose correction's compute time;
//  - the scans a correction escalates to when the content's steps fail their check (a
//    projector zoomed 2 %: no pose with the old intrinsics explains it): the coarse Gray
//    pass (Gray code alone, one code per 8 px) against the full scan (Gray code and
//    phase shift): frames, decode and solve time (route (b′) on the wall), and the
//    collineation's error against the true zoomed projector.
// Writes drift.csv, drift_scans.csv (and drift_soak.csv) to --out DIR.
//
//   bench_drift [--out DIR] [--runs N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <vector>

#include "bench_timing.hpp"
#include "blend/rig_tiles.hpp"
#include "calibration/plane_homography_route.hpp"
#include "core/units.hpp"
#include "drift/misregistration.hpp"
#include "drift/projector_camera_map.hpp"
#include "drift/projector_correction.hpp"
#include "drift/reference_blur.hpp"
#include "drift/shown_light.hpp"
#include "geometry/intersect.hpp"
#include "geometry/yaw_pitch_roll.hpp"
#include "render/cpu_renderer.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "structured_light/decoder.hpp"
#include "structured_light/pattern_set.hpp"
#include "unit/drift/textured_content.hpp"

namespace {

using namespace procam;

cv::Mat textContent(cv::Size size) {
  cv::Mat m(size, CV_8U, cv::Scalar(255));
  const char* lines[] = {"Projector-based displays keep",  "themselves registered while",
                         "content plays: each tile of",    "the frame is found again in",
                         "the camera's view of the wall.", "0123456789 ABCDEFGHIJKLM"};
  int y = 120;
  for (const char* l : lines) {
    cv::putText(m, l, {80, y}, cv::FONT_HERSHEY_SIMPLEX, 2.4, cv::Scalar(0), 5, cv::LINE_AA);
    y += 160;
  }
  return m;
}

cv::Mat gradientContent(cv::Size size) {
  cv::Mat m(size, CV_8U);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      m.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(
          255.0 * (0.5 + 0.5 * std::sin(x / 300.0) * std::cos(y / 200.0)));
    }
  }
  return m;
}

geom::Pose turned(const geom::Pose& pose, double yaw_deg) {
  geom::YawPitchRoll a;
  a.yaw = degToRad(yaw_deg);
  const Mat3 Q = geom::parentFromChild(a);
  return {Q.transpose() * pose.R, Q.transpose() * pose.t};
}

struct Setup {
  sim::Scene scene;
  rig::RigModel rig;
  geom::PlaneHomography tile;
  drift::WorkGrid grid{{1920, 1080}, 2};
  cv::Mat map;
};

// The camera's radiance of `fb` shown with the projector at `pose` (cast once), and its
// images with new noise.
struct Camera {
  const sim::CameraSpec* spec = nullptr;
  cv::Mat radiance;
  cv::Mat frame(uint64_t seed, int average) const {
    cv::Mat sum;
    for (int i = 0; i < average; ++i) {
      sim::RenderOptions o;
      o.seed = seed * 16 + i;
      cv::Mat img = sim::Renderer::cameraImage(*spec, radiance, o), f;
      img.convertTo(f, CV_32F);
      if (sum.empty()) sum = cv::Mat::zeros(f.size(), CV_32F);
      sum += f;
    }
    return sum / average;
  }
};

Camera cameraOf(const Setup& s, const cv::Mat& fb, const geom::Pose& pose) {
  sim::SceneState st = s.scene.at(0);
  st.projectors.at(0).model.pose = pose;
  auto r = sim::Renderer::create(s.scene, st, {{"proj", fb}});
  Camera c;
  c.spec = &s.scene.cameras().at(0);
  c.radiance = *r->cameraRadiance("cam");
  return c;
}

// The frame's light, through the projector's true response (as the daemon's reference).
cv::Mat shownOf(const Setup& s, const cv::Mat& fb) {
  auto light = drift::shownLight(fb, s.scene.at(0).projectors.at(0).spec.gamma, s.grid);
  return light ? *light : cv::Mat();
}

// The true shift, in framebuffer pixels, of the content drawn at `p` when the projector
// is at `pose` (where the rig at rest puts the wall point it lands on).
Vec2 trueShift(const Setup& s, const geom::Pose& pose, const Vec2& p) {
  geom::CameraModel rest = s.scene.at(0).projectors.at(0).model, moved = rest;
  moved.pose = pose;
  auto hit = geom::intersectPlane(*moved.backproject(p), *s.rig.surface.plane);
  return *rest.project(hit->point) - p;
}

// RMS of the true shift over the framebuffer (every 60 px inside the camera's view).
double trueRms(const Setup& s, const geom::Pose& pose) {
  double sq = 0;
  int n = 0;
  for (int y = 30; y < 1080; y += 60) {
    for (int x = 30; x < 1920; x += 60) {
      const cv::Vec2f c = s.map.at<cv::Vec2f>(s.grid.toWork({x, y}).y(), s.grid.toWork({x, y}).x());
      if (c[0] < 0) continue;
      sq += trueShift(s, pose, {x, y}).squaredNorm();
      ++n;
    }
  }
  return n ? std::sqrt(sq / n) : 0.0;
}

// OpenCV's ECC homography between the frame shown and the camera's view on the grid:
// the RMS of its shift field against the truth, framebuffer px (NaN when it fails).
double eccError(const Setup& s, const cv::Mat& shown, const cv::Mat& camera,
                const geom::Pose& pose) {
  cv::Mat seen;
  cv::remap(camera, seen, s.map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::Mat mask;
  cv::extractChannel(s.map, mask, 0);
  mask = mask >= 0;
  cv::Mat W = cv::Mat::eye(3, 3, CV_32F);
  try {
    cv::findTransformECC(
        shown, seen, W, cv::MOTION_HOMOGRAPHY,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-6), mask, 5);
  } catch (const cv::Exception&) {
    return std::nan("");
  }
  // input(W x) = template(x): the content drawn at x is seen at W(x).
  double sq = 0;
  int n = 0;
  for (int y = 30; y < 1080; y += 60) {
    for (int x = 30; x < 1920; x += 60) {
      const Vec2 w = s.grid.toWork({x, y});
      if (s.map.at<cv::Vec2f>(int(w.y()), int(w.x()))[0] < 0) continue;
      cv::Mat q = W * (cv::Mat_<float>(3, 1) << float(w.x()), float(w.y()), 1.f);
      const Vec2 seen_at =
          s.grid.toFramebuffer({q.at<float>(0) / q.at<float>(2), q.at<float>(1) / q.at<float>(2)});
      sq += ((seen_at - Vec2(x, y)) - trueShift(s, pose, {x, y})).squaredNorm();
      ++n;
    }
  }
  return std::sqrt(sq / std::max(1, n));
}

}  // namespace

// A scan of the projector `state` holds (route (b′) on the rig's wall): the camera's
// captures of every frame of `set` (rendered once, new noise each), then decode and solve
// timed; the error is the largest distance, in the true projector's pixels, between a
// framebuffer pixel and where the true projector puts the wall point the collineation
// gives it (every 40 px).
struct ScanFigures {
  int frames = 0;
  double decode_ms = 0, solve_ms = 0, error_px = 0;
  std::string failed;
};
ScanFigures scanFigures(const Setup& s, const sim::SceneState& state, const sl::PatternSet& set,
                        int runs) {
  ScanFigures f;
  f.frames = static_cast<int>(set.frames.size());
  std::vector<cv::Mat> captures;
  for (std::size_t i = 0; i < set.frames.size(); ++i) {
    auto r = sim::Renderer::create(s.scene, state, {{"proj", sl::renderFrame(set, i)}});
    sim::RenderOptions o;
    o.seed = 500 + i;
    captures.push_back(
        sim::Renderer::cameraImage(s.scene.cameras().at(0), *r->cameraRadiance("cam"), o));
  }
  const geom::CameraModel cam = s.rig.cameras.at(0).model;
  Result<sl::Decoded> decoded = fail(ErrorCode::kInvalidInput, "not decoded");
  f.decode_ms = bench::measure(runs, [&] { decoded = sl::decode(set, captures); }).median_ms;
  if (!decoded) {
    f.failed = decoded.error().message;
    return f;
  }
  const calib::DecodedView view{"cam", cam, *decoded};
  calib::PlaneHomographyOptions options;
  options.step = set.options.mode == sl::Mode::kGray ? 16 : 8;  // the daemon's grids
  Result<calib::PlaneHomographyResult> solved = fail(ErrorCode::kInvalidInput, "not solved");
  f.solve_ms = bench::measure(runs, [&] {
                 solved =
                     calib::solvePlaneHomographyRoute(set, view, *s.rig.surface.plane, options);
               }).median_ms;
  if (!solved) {
    f.failed = solved.error().message;
    return f;
  }
  const geom::CameraModel& truth = state.projectors.at(0).model;
  const geom::PlaneHomography& h = solved->projector_to_plane;
  for (int y = 0; y < truth.height; y += 40) {
    for (int x = 0; x < truth.width; x += 40) {
      const Vec3 ab = h.H * Vec3(x, y, 1.0);
      auto back = truth.project(h.basis.toWorld({ab.x() / ab.z(), ab.y() / ab.z()}));
      f.error_px = std::max(f.error_px, back ? (*back - Vec2(x, y)).norm() : 1e9);
    }
  }
  return f;
}

int main(int argc, char** argv) {
  std::filesystem::path out = "bench-out/bench_drift";
  int runs = 20;
  if (!bench::benchOptions(argc, argv, "bench_drift", out, runs, 5)) return 2;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // a line at a time: the soak runs ten minutes
  Setup s{*sim::resolveScene("wall_oblique"), {}, {}, drift::WorkGrid{{1920, 1080}, 2}, {}};
  s.rig = *sim::truthRig(s.scene, 0.0);
  s.tile = blend::displayTile(s.rig.projectors.at(0), s.rig.surface)->projector_to_plane;
  const geom::CameraModel cam = s.rig.cameras.at(0).model;
  s.map = *drift::projectorCameraMap(s.tile, cam, s.grid);
  const geom::Pose rest = s.scene.at(0).projectors.at(0).model.pose;

  std::ofstream csv(out / "drift.csv");
  csv << "content,reference_ms,measure_ms,ecc_ms,frame_period_ms,blur_px,floor_p99_px,bump_deg,"
         "true_px,"
         "measured_px,ecc_error_px,correct_ms\n";
  std::printf(
      "Drift check on wall_oblique (1920x1080 projector, 1280x960 camera, 0.8 DN), grid "
      "%dx%d, %d runs\n",
      s.grid.size().width, s.grid.size().height, runs);
  struct Content {
    const char* name;
    cv::Mat fb;
  };
  const Content contents[] = {
      {"natural", drift::texturedContent({1920, 1080}, 5, {96, 32, 12})},
      {"text", textContent({1920, 1080})},
      {"gradient", gradientContent({1920, 1080})},
  };
  for (const Content& c : contents) {
    const cv::Mat shown = shownOf(s, c.fb);
    // The reference: the frame drawn again (a 1:1 CPU render of the RGBA frame) and mapped.
    cv::Mat rgba;
    cv::cvtColor(c.fb, rgba, cv::COLOR_GRAY2RGBA);
    render::RenderSetup setup;
    setup.output_size = c.fb.size();
    setup.content_size = c.fb.size();
    const bench::Timing ref = bench::measure(runs, [&] {
      render::CpuRenderer cpu;
      (void)cpu.configure(setup);
      (void)cpu.render(render::Content(&rgba, nullptr, 1));
      (void)drift::projectorCameraMap(s.tile, cam, s.grid);
    });
    const Camera at_rest = cameraOf(s, c.fb, rest);
    std::vector<double> floor;
    const cv::Mat frame0 = at_rest.frame(1, 2);
    // As the daemon does: the blur the camera sees the frame with, fitted once at rest.
    drift::MisregistrationOptions options;
    const bench::Timing fit = bench::measure(std::max(3, runs / 4), [&] {
      auto b = drift::fitReferenceBlur(shown, frame0, s.map, s.grid);
      options.reference_blur_px = b && b->sigma_px ? *b->sigma_px : 0.0;
    });
    const bench::Timing meas = bench::measure(
        runs, [&] { (void)drift::measureMisregistration(shown, frame0, s.map, s.grid, options); });
    for (int i = 0; i < 4 * runs; ++i) {
      auto m =
          drift::measureMisregistration(shown, at_rest.frame(100 + i, 2), s.map, s.grid, options);
      floor.push_back(m && !m->too_plain ? m->rms_px : std::nan(""));
    }
    const bool plain =
        std::any_of(floor.begin(), floor.end(), [](double v) { return std::isnan(v); });
    std::sort(floor.begin(), floor.end());
    const double p99 =
        plain ? std::nan("") : floor[std::min(floor.size() - 1, floor.size() * 99 / 100)];
    const bench::Timing ecc =
        bench::measure(std::max(3, runs / 4), [&] { (void)eccError(s, shown, frame0, rest); });
    std::printf(
        "  %-9s reference %.1f ms, check %.1f ms (a 30 fps camera: 33.3 ms per frame); "
        "OpenCV ECC homography %.1f ms (%.1fx); blur %.2f work px (fitted once in %.0f ms); at "
        "rest %s\n",
        c.name, ref.median_ms, meas.median_ms, ecc.median_ms, ecc.median_ms / meas.median_ms,
        options.reference_blur_px, fit.median_ms,
        plain ? "too plain to tell" : ("p99 " + std::to_string(p99) + " px").c_str());
    for (double bump : {0.0, 0.005, 0.01, 0.02, 0.05, 0.5}) {
      const geom::Pose pose = turned(rest, bump);
      const Camera moved = cameraOf(s, c.fb, pose);
      const cv::Mat frame = moved.frame(7, 2);
      auto m = drift::measureMisregistration(shown, frame, s.map, s.grid, options);
      const double truth = trueRms(s, pose);
      const double ecc_err = eccError(s, shown, frame, pose);
      double correct_ms = std::nan("");
      if (m && !m->too_plain && bump > 0) {
        correct_ms = bench::measure(runs, [&] {
                       (void)drift::correctProjector(s.rig.projectors.at(0), s.tile, *m);
                     }).median_ms;
      }
      const double measured = m && !m->too_plain ? m->rms_px : std::nan("");
      std::printf("    yaw %.3f deg: true %.3f px, measured %.3f px, ECC error %.3f px%s\n", bump,
                  truth, measured, ecc_err,
                  std::isnan(correct_ms)
                      ? ""
                      : (", correction " + std::to_string(correct_ms) + " ms").c_str());
      csv << c.name << "," << ref.median_ms << "," << meas.median_ms << "," << ecc.median_ms
          << ",33.3," << options.reference_blur_px << "," << p99 << "," << bump << "," << truth
          << "," << measured << "," << ecc_err << "," << correct_ms << std::endl;
    }
  }

  // The scans, of the projector zoomed 2 %.
  {
    sim::SceneState zoomed = s.scene.at(0);
    geom::Intrinsics& K = zoomed.projectors.at(0).model.K;
    K.fx *= 1.02;
    K.fy *= 1.02;
    std::ofstream scans(out / "drift_scans.csv");
    scans << "scan,frames,decode_ms,solve_ms,error_px\n";
    std::printf("Scans of the projector zoomed 2 %% (route (b') on the wall, %d runs):\n",
                std::max(3, runs / 4));
    struct Scan {
      const char* name;
      sl::Mode mode;
      int step;
    };
    for (const Scan& sc :
         {Scan{"coarse", sl::Mode::kGray, 8}, Scan{"full", sl::Mode::kGrayPhase, 1}}) {
      sl::PatternOptions po;
      po.width = 1920;
      po.height = 1080;
      po.mode = sc.mode;
      po.step = sc.step;
      const ScanFigures f = scanFigures(s, zoomed, *sl::makePatternSet(po), std::max(3, runs / 4));
      std::printf(
          "  %-6s %d frames (%.2f s at 60 Hz with 2 settle frames and one capture each), decode "
          "%.0f ms, solve %.0f ms; the collineation %.3f px from the true projector (max)%s\n",
          sc.name, f.frames, f.frames * 4 / 60.0, f.decode_ms, f.solve_ms, f.error_px,
          f.failed.empty() ? "" : (": failed: " + f.failed).c_str());
      scans << sc.name << "," << f.frames << "," << f.decode_ms << "," << f.solve_ms << ","
            << f.error_px << std::endl;
    }
  }

  // Ten minutes still at 4 checks per second.
  const Content& natural = contents[0];
  const cv::Mat shown = shownOf(s, natural.fb);
  const Camera at_rest = cameraOf(s, natural.fb, rest);
  drift::MisregistrationOptions soak_options;
  if (auto b = drift::fitReferenceBlur(shown, at_rest.frame(1, 2), s.map, s.grid);
      b && b->sigma_px) {
    soak_options.reference_blur_px = *b->sigma_px;
  }
  std::ofstream soak(out / "drift_soak.csv");
  soak << "check,misregistration_px\n";
  const int checks = 10 * 60 * 4;
  const int settle_checks = 2;  // 0.5 s at 4 per second
  double worst = 0;
  int run = 0, false_triggers = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < checks; ++i) {
    auto m = drift::measureMisregistration(shown, at_rest.frame(10'000 + i, 2), s.map, s.grid,
                                           soak_options);
    const double v = m && !m->too_plain ? m->rms_px : 0.0;
    worst = std::max(worst, v);
    run = v > 0.5 ? run + 1 : 0;
    if (run == settle_checks + 1) ++false_triggers;
    soak << i << "," << v << "\n";
  }
  std::printf(
      "Still soak: %d checks (10 min at 4 per second, 2 frames each) in %.0f s: largest "
      "misregistration %.3f px (threshold 0.5), %d false recalibration(s)\n",
      checks, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), worst,
      false_triggers);
  return 0;
}
