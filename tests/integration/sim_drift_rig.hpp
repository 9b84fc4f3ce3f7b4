#pragma once
// The on-drift end-to-end tests' rig (test_sim_drift.cpp, test_sim_drift_plain.cpp):
// wall_oblique (one 1920x1080 projector at 30 deg yaw / 15 deg pitch to a wall, one fixed
// camera with 0.8 DN read noise) with scene events appended, procamd on it with the
// scene's truth at rest as its rig model, content shown through `keystone rig on`, and
// the corrected rig judged against the TRUE projector.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "daemon_harness.hpp"
#include "geometry/intersect.hpp"
#include "keystone_truth.hpp"
#include "rig/rig_model.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"
#include "unit/drift/second_camera.hpp"
#include "unit/drift/textured_content.hpp"

namespace procam::itest {

using Clock = std::chrono::steady_clock;

// A projector turned at scene time t (seconds) in its own frame (degrees).
struct Bump {
  double t;
  double yaw, pitch;
};

// Scene events run on the wall clock; under the sanitizers the daemon and the virtual
// camera are kSlowdown times slower, so the scene's times stretch with them.
inline double at(double seconds) {
  return seconds * kSlowdown;
}
inline std::string atText(double seconds) {
  return std::to_string(at(seconds));
}

// wall_oblique with `events` appended, written into `dir`.
inline std::string sceneWithEvents(const TempDir& dir, const std::string& events) {
  const char* src = std::getenv("PROCAM_SOURCE_DIR");
  std::ifstream in(std::string(src ? src : ".") + "/tests/scenes/wall_oblique.toml");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_FALSE(text.str().empty()) << "PROCAM_SOURCE_DIR must name the source tree";
  dir.write("wall_drift.toml", text.str() + "\n" + events);
  return dir.file("wall_drift.toml");
}

// A natural image's spectrum, 1600x900, as a content file.
inline std::string texturedContent(const TempDir& dir) {
  cv::Mat rgb;
  cv::cvtColor(drift::texturedContent({1600, 900}, 11, {80, 27, 9}), rgb, cv::COLOR_GRAY2BGR);
  const std::string png = contentFile(dir, "texture.png");
  cv::imwrite(png, rgb);
  return png;
}

// rig.json in the daemon's state directory, as text.
inline std::string rigText(const TempDir& dir) {
  std::ifstream f(dir.file("state/rig.json"));
  std::stringstream text;
  text << f.rdbuf();
  return text.str();
}

// procamd on `scene_file` with `recalibrate = POLICY` and the scene's truth at rest as
// its rig model.
inline DaemonProcess::Launch driftDaemon(const TempDir& dir, const std::string& policy,
                                         const std::string& scene_file,
                                         std::vector<std::string> env = {},
                                         const std::string& more_policy = "") {
  dir.write("procamd.toml", "[policy]\nrecalibrate = \"" + policy + "\"\n" + more_policy);
  return {{"--config", dir.file("procamd.toml"), "--sim", scene_file, "--rig",
           truthRigFile(dir, scene_file)},
          std::move(env),
          -1,
          true};
}

// When the daemon started, by its uptime: the virtual rig's clock starts a little later,
// so scene times measured from here are upper bounds.
inline Clock::time_point daemonStart(Connection& c) {
  const auto now = Clock::now();
  auto st = c.call({{"cmd", "status"}});
  EXPECT_TRUE(st);
  const double up = st ? (*st)["uptime_s"].get<double>() : 0.0;
  return now - std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(up));
}

// Starts the scene's content through the rig's keystone; the daemon is started by the
// caller with the truth at rest as its rig.
inline void showContent(Connection& c, const std::string& png) {
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}});
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();
}

inline json outputDrift(Connection& c) {
  auto st = c.call({{"cmd", "status"}});
  if (!st || (*st)["outputs"]["shown"].empty()) return nullptr;
  return (*st)["outputs"]["shown"][0].value("drift", json(nullptr));
}

// Whether an output's drift status (`drift()`) counts `n` checks within `within`.
template <class DriftOf>
bool checkedTimes(DriftOf drift, int n, std::chrono::seconds within) {
  return eventually(
      [&] {
        const json dr = drift();
        return dr.is_object() && dr.value("checks", 0) >= n;
      },
      within * kSlowdown);
}

// The rig model's projector (rig.json as the daemon wrote it) against the true one:
// the largest distance, in the true projector's pixels, between a framebuffer pixel
// and where the true projector puts the wall point the rig gives that pixel (by its
// pose, or by its collineation with the wall when the rig knows only that).
inline double rigAgainstTruth(const TempDir& dir, const geom::CameraModel& truth) {
  auto rig = rig::rigFromText(rigText(dir), "rig.json");
  EXPECT_TRUE(rig) << rig.error().message;
  if (!rig) return 1e9;
  const rig::RigProjector& p = rig->projectors.at(0);
  const geom::CameraModel model = p.model();
  const bool posed = p.pose_known && p.intrinsics_known;
  if (!posed && !p.plane_homography) return 1e9;
  const auto wallPoint = [&](int x, int y) -> std::optional<Vec3> {
    if (!posed) {
      const Vec3 ab = p.plane_homography->H * Vec3(x, y, 1.0);
      return p.plane_homography->basis.toWorld({ab.x() / ab.z(), ab.y() / ab.z()});
    }
    auto ray = model.backproject({x, y});
    auto hit = ray ? geom::intersectPlane(*ray, *rig->surface.plane) : std::nullopt;
    return hit ? std::optional<Vec3>(hit->point) : std::nullopt;
  };
  double worst = 0;
  for (int y = 0; y < p.height; y += 40) {
    for (int x = 0; x < p.width; x += 40) {
      auto hit = wallPoint(x, y);
      auto back = hit ? truth.project(*hit) : std::nullopt;
      if (!back) return 1e9;
      worst = std::max(worst, (*back - Vec2(x, y)).norm());
    }
  }
  return worst;
}

// The keystone the daemon shows now against the true projector.
inline Measured keystoneAgainstTruth(Connection& c, const geom::CameraModel& truth) {
  auto k = c.call({{"cmd", "keystone"}});
  EXPECT_TRUE(k && (*k)["mode"] == "rig") << (k ? k->dump() : "");
  if (!k || (*k)["mode"] != "rig") return {1e9, 1, 1};
  return measureAgainstTruth(truth.K, truth.pose.R, truth.width, truth.height,
                             matrixOf((*k)["homography"]), (*k)["content_size"][0],
                             (*k)["content_size"][1]);
}

// The `drift` event of the correction `state` (none of `wrong`, none unresolved), then
// whether a check found the output registered after it (within `within`, 25 s unless a
// scan's frames must be filmed first).
inline std::optional<json> awaitCorrection(Connection& watcher, const std::string& state,
                                           const std::string& wrong, bool& registered,
                                           std::chrono::seconds within = 25s) {
  std::optional<json> corrected;
  registered = false;
  const auto deadline = Clock::now() + within * kSlowdown;
  while (Clock::now() < deadline && !registered) {
    auto e = watcher.next(1s);
    if (!e || (*e)["event"] != "drift") continue;
    EXPECT_NE((*e)["state"], wrong) << e->dump();
    EXPECT_NE((*e)["state"], "unresolved") << e->dump();
    if ((*e)["state"] == state) corrected = *e;
    registered = corrected && (*e)["state"] == "corrected";
  }
  return corrected;
}

// procamd with recalibrate = `policy` (default "on-drift") on wall_oblique with a second
// camera (or with its one) and `events`, a watcher on its events and textured content
// shown.
struct DriftRig {
  DriftRig(const TempDir& dir, const std::string& events, bool second_camera = true,
           const std::string& more_policy = "", const std::string& policy = "on-drift")
      : scene_file(sceneWithEvents(
            dir, (second_camera ? std::string(drift::kSecondCamera) : std::string()) + events)),
        scene(sim::resolveScene(scene_file)),
        d(dir, driftDaemon(dir, policy, scene_file, {}, more_policy)),
        c(d.socketPath()),
        watcher(d.socketPath()) {}
  // Fatal failures of the set-up; call first. `png`: the content (default: textured).
  void start(const TempDir& dir, std::string png = "") {
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_TRUE(d.started()) << d.log();
    ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
    if (png.empty()) png = texturedContent(dir);
    ASSERT_NO_FATAL_FAILURE(showContent(c, png));
  }
  std::string scene_file;
  Result<sim::Scene> scene;
  DaemonProcess d;
  Connection c, watcher;
};

// The course of the tests that check an output now and then (fiducial frames, a stream's
// held frames) on wall_oblique, one check every 2 s: the projector turned 1 degree at 14
// s. Under "on-drift" (`held` false) the checks are fiducial frames, under
// "on-drift-silent" a stream's frames held for a capture. The first comes 3 to 4 s after
// the daemon starts on two idle cores (start, content, the first checks), then one every
// 3 s or so (a 2 s period, and a second for the virtual camera to render each new frame);
// on two busy cores a capture takes 3 s.
struct BumpCourse {
  explicit BumpCourse(const TempDir& dir, bool held = false)
      : held(held),
        bump_t(at(14.0)),
        scene_file(sceneWithEvents(dir, "[[events]]\nt = " + std::to_string(bump_t) +
                                            "\ntarget = \"proj\"\nrotate_deg = [1.0, 0.0, 0.0]\n")),
        scene(sim::resolveScene(scene_file)),
        d(dir, driftDaemon(dir, held ? "on-drift-silent" : "on-drift", scene_file, {},
                           held ? "drift_stream_period_s = 2\n" : "drift_fiducial_period_s = 2\n")),
        c(d.socketPath()),
        watcher(d.socketPath()) {}
  // Fatal failures of the set-up; call first.
  void start() {
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_TRUE(d.started()) << d.log();
    ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
    started = daemonStart(c);
  }
  double sceneTime() const { return std::chrono::duration<double>(Clock::now() - started).count(); }
  // The drift status just before the bump (the scene's clock starts after the daemon's: a
  // margin of 1 s), checked against `before` (rig.json once the content showed): two
  // checks or more, under half the 0.5 px threshold (no false trigger), nothing corrected.
  json still(const TempDir& dir, const std::string& before, const std::string& content) {
    while (sceneTime() < bump_t - 1.0) std::this_thread::sleep_for(100ms);
    const json dr = outputDrift(c);
    EXPECT_TRUE(dr.is_object()) << dr.dump();
    if (!dr.is_object()) return dr;
    const int checks = held ? dr["held"].value("checks", 0) : dr["fiducial"].value("frames", 0);
    const double px = held ? dr.value("misregistration_px", 1e9)
                           : dr["fiducial"].value("misregistration_px", 1e9);
    std::printf(
        "[ figures  ] still, %s: %d %s in %.1f s, misregistration %.3f px; %d corrections\n",
        content.c_str(), checks, held ? "held frames" : "fiducial frames", sceneTime(), px,
        dr.value("corrections", -1));
    EXPECT_GE(checks, 2) << dr.dump();
    EXPECT_EQ(dr.value("corrections", -1), 0) << dr.dump();
    EXPECT_LT(px, 0.25) << dr.dump();
    EXPECT_EQ(before, rigText(dir));
    return dr;
  }
  // The bump found at a check, the projector corrected from its correspondences (tag
  // corners or content tiles) and registered again: the rig against the true projector
  // within the 0.5 px threshold.
  void corrected(const TempDir& dir, const std::string& content) {
    bool registered = false;
    const std::optional<json> corrected =
        awaitCorrection(watcher, "corrected-pose", "corrected-surface", registered);
    ASSERT_TRUE(corrected) << outputDrift(c).dump() << d.log();
    const double corrected_after = sceneTime() - bump_t;
    EXPECT_TRUE(registered) << outputDrift(c).dump();
    const json dr = outputDrift(c);
    const double rig_px = rigAgainstTruth(dir, scene->at(bump_t + at(1.0)).projectors.at(0).model);
    std::printf(
        "[ figures  ] projector bumped 1 deg under %s: seen at %.2f px, corrected from %d "
        "%s (pose fit %.3f px), registered within %.1f s of the bump (a check every 2 s); "
        "the rig against the true projector %.3f px; %d %s in all\n",
        content.c_str(), (*corrected)["why"]["misregistration_px"].get<double>(),
        (*corrected)["tiles"].get<int>(), held ? "content tiles" : "tag corners",
        (*corrected)["pose_fit_px"].get<double>(), corrected_after, rig_px,
        held ? dr["held"].value("checks", 0) : dr["fiducial"].value("frames", 0),
        held ? "held frames" : "fiducial frames");
    EXPECT_LE(rig_px, 0.5);
  }
  bool held;
  double bump_t;
  std::string scene_file;
  Result<sim::Scene> scene;
  DaemonProcess d;
  Connection c, watcher;
  Clock::time_point started;
};

}  // namespace procam::itest
