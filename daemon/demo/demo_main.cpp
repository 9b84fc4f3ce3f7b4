// procam-demo: a scripted sequence on the virtual rig. Every frame the projector
// shows a checkerboard, the rig's camera captures it (rendered with noise), the
// corners are found and a projector -> camera homography is fitted; the tilt
// sensor's gravity reading gives the projector's tilt. Each step is compared with
// the rig's ground truth and the error printed.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/calib3d.hpp>
#include <string>
#include <string_view>

#include "demo/checkerboard.hpp"
#include "geometry/homography.hpp"
#include "sim/orientation.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/sensors.hpp"

namespace {

using procam::Points2;
using procam::Vec2;
using procam::Vec3;
using procam::Mat3;
namespace geom = procam::geom;
namespace sim = procam::sim;

struct Options {
  std::string scene = "handheld";
  int frames = 6;
  int square = 96;
};

void usage() {
  std::puts(
      "usage: procam-demo [--scene NAME|FILE] [--frames N]\n"
      "Runs a scripted sequence on the virtual rig and prints, per frame, what was\n"
      "done and its error against ground truth. Default scene: handheld.");
}

bool parseArgs(int argc, char** argv, Options& out) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") {
      usage();
      std::exit(0);
    }
    if (i + 1 >= argc) return false;
    if (a == "--scene") {
      out.scene = argv[++i];
    } else if (a == "--frames") {
      out.frames = std::atoi(argv[++i]);
      if (out.frames < 1 || out.frames > 1000) return false;
    } else {
      return false;
    }
  }
  return true;
}

double rms(const Points2& a, const Points2& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]).squaredNorm();
  return std::sqrt(s / static_cast<double>(a.size()));
}

// True ideal (undistorted) camera pixel of each projector framebuffer point:
// projector ray -> nearest surface -> camera. Points hidden from the camera are
// marked invalid.
bool truthCorners(const sim::Scene& scene, const geom::CameraModel& proj,
                  const geom::CameraModel& cam, const Points2& fb, Points2& out) {
  geom::CameraModel ideal = cam;
  ideal.dist = {};
  out.clear();
  for (const Vec2& p : fb) {
    auto ray = proj.backproject(p);
    if (!ray) return false;
    auto hit = scene.world().intersect(*ray);
    if (!hit) return false;
    const Vec3 x = hit->hit.point;
    const Vec3 c = cam.pose.center();
    geom::Ray back{c, (x - c).normalized()};
    if (scene.world().occluded(back, (x - c).norm() * (1 - 1e-9))) return false;
    auto px = ideal.project(x);
    if (!px) return false;
    out.push_back(*px);
  }
  return true;
}

// Tilt of the projector's optical axis against the horizon and roll about it, in
// degrees, from gravity expressed in the projector frame (x right, y down, z fwd).
void tiltFromGravity(const Vec3& down, double& pitch_deg, double& roll_deg) {
  const Vec3 g = down.normalized();
  pitch_deg = sim::radToDeg(std::asin(std::clamp(-g.z(), -1.0, 1.0)));
  roll_deg = sim::radToDeg(std::atan2(-g.x(), g.y()));
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!parseArgs(argc, argv, opt)) {
    usage();
    return 2;
  }
  auto scene_or = sim::resolveScene(opt.scene);
  if (!scene_or) {
    std::fprintf(stderr, "procam-demo: %s\n", scene_or.error().message.c_str());
    return 1;
  }
  const sim::Scene& scene = *scene_or;
  if (scene.projectors().empty() || scene.cameras().empty()) {
    std::fprintf(stderr, "procam-demo: scene '%s' needs a projector and a camera\n",
                 scene.name().c_str());
    return 1;
  }
  const auto& pspec = scene.projectors().front();
  const auto& cspec = scene.cameras().front();
  double duration = 0;
  for (const auto& tr : scene.trajectories()) duration = std::max(duration, tr.duration());
  const auto board = procam::demo::makeCheckerboard(pspec.width, pspec.height, opt.square);

  std::printf("procam-demo: scene '%s' — projector '%s' %dx%d, camera '%s' %dx%d, %d frame(s)\n",
              scene.name().c_str(), pspec.name.c_str(), pspec.width, pspec.height,
              cspec.name.c_str(), cspec.width, cspec.height, opt.frames);
  int failures = 0;
  for (int f = 0; f < opt.frames; ++f) {
    const double t = opt.frames > 1 ? duration * f / (opt.frames - 1) : 0.0;
    const sim::SceneState state = scene.at(t);
    const auto& proj = state.projectors.front().model;
    const auto& cam = state.cameras.front().model;
    std::printf("frame %d  t=%.2fs\n", f, t);

    // Tilt sensor on this projector: its gravity reading against the true tilt.
    for (const auto& ts : scene.tiltSensors()) {
      if (ts.projector != pspec.name) continue;
      auto sample = sim::sampleTilt(scene, ts.name, t, 1000 + f);
      if (!sample) continue;
      const Mat3 projector_from_sensor = ts.sensor_from_projector.transpose();
      double p_meas, r_meas, p_true, r_true;
      tiltFromGravity(-(projector_from_sensor * sample->value), p_meas, r_meas);
      tiltFromGravity(-(projector_from_sensor * sample->truth), p_true, r_true);
      std::printf("  tilt   '%s': pitch %+7.2f° (true %+7.2f°, error %.3f°)  roll %+7.2f° "
                  "(true %+7.2f°, error %.3f°)  [uncalibrated sensor]\n",
                  ts.name.c_str(), p_meas, p_true, std::abs(p_meas - p_true), r_meas, r_true,
                  std::abs(r_meas - r_true));
    }

    sim::Framebuffers shown;
    shown.emplace(pspec.name, board.image);
    auto renderer = sim::Renderer::create(scene, state, shown);
    if (!renderer) {
      std::printf("  render failed: %s\n", renderer.error().message.c_str());
      ++failures;
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto image = renderer->renderCamera(cspec.name, {.noise = true, .seed = 7u + f});
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!image) {
      std::printf("  render failed: %s\n", image.error().message.c_str());
      ++failures;
      continue;
    }
    std::printf("  render camera '%s' with checkerboard shown: %.0f ms\n", cspec.name.c_str(), ms);

    Points2 truth;
    if (!truthCorners(scene, proj, cam, board.corners, truth)) {
      std::printf("  checkerboard: not fully visible to the camera at this pose, skipped\n");
      continue;
    }
    cv::Mat gray = *image;
    if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U, 255.0 / cspec.maxDn());
    std::vector<cv::Point2f> found;
    if (!cv::findChessboardCornersSB(gray, board.inner, found, cv::CALIB_CB_ACCURACY)) {
      std::printf("  checkerboard: not detected (%d x %d inner corners)\n", board.inner.width,
                  board.inner.height);
      ++failures;
      continue;
    }
    Points2 detected;
    for (const auto& p : found) {
      auto u = cam.undistortPixel(Vec2(p.x, p.y));
      detected.push_back(u ? *u : Vec2(p.x, p.y));
    }
    // The detector may start from the opposite corner of the board.
    if ((detected.front() - truth.front()).norm() > (detected.back() - truth.front()).norm()) {
      std::reverse(detected.begin(), detected.end());
    }
    const double detect_rms = rms(detected, truth);
    auto fit = geom::fitHomography(board.corners, detected);
    if (!fit) {
      std::printf("  homography: %s (%s)\n", fit.error().message.c_str(),
                  procam::toString(fit.error().code));
      ++failures;
      continue;
    }
    Points2 mapped;
    for (const Vec2& p : board.corners) mapped.push_back(*geom::applyHomography(fit->H, p));
    std::printf("  corners: %zu found, detection error %.3f px RMS against truth\n",
                detected.size(), detect_rms);
    std::printf("  homography projector->camera: residual %.3f px RMS, condition %.1f, "
                "transfer error against truth %.3f px RMS\n",
                fit->rms, fit->condition, rms(mapped, truth));
  }
  std::printf("procam-demo: done, %d frame(s) failed\n", failures);
  return failures == 0 ? 0 : 1;
}
