#pragma once
// The calibrate operation's runs on corner_stereo at half resolution, shared by the
// daemon_calibrate_tests sources: the scene, the request, and reading a run to its end.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "daemon_harness.hpp"
#include "sim/scene.hpp"
#include "unit/calibration/rig_capture.hpp"

namespace procam::itest {

// Projector 640x400 and cameras 512x384 (corner_stereo's scaled by 1/2, intrinsics
// with them), as in tests/unit/calibration/test_rig_accuracy.cpp; with
// projector_scale 1 the projector keeps its 1280x800.

inline std::string sceneFile(const TempDir& dir, double projector_scale = 0.5) {
  std::string t = procam::testing::sceneText("corner_stereo");
  EXPECT_TRUE(procam::testing::scaleDevice(t, 1280, 800, projector_scale));  // proj
  EXPECT_TRUE(procam::testing::scaleDevice(t, 1024, 768, 0.5));              // cam_left
  EXPECT_TRUE(procam::testing::scaleDevice(t, 1024, 768, 0.5));              // cam_right
  dir.write("corner_small.toml", t);
  return dir.file("corner_small.toml");
}

inline geom::CameraModel projectorTruth(const std::string& scene_file) {
  auto scene = sim::Scene::load(scene_file);
  EXPECT_TRUE(scene) << scene.error().message;
  return scene->at(0).projectors.at(0).model;
}

inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The request the tests run: Gray code + 3-step phase, nodes every 8 projector
// pixels, no settle wait (the mock output shows a frame at once).
inline json calibrateRequest(int id) {
  return {{"cmd", "calibrate"}, {"id", id},  {"mode", "gray+phase"},
          {"phase_steps", 3},   {"grid", 8}, {"settle_frames", 0}};
}

struct CalibrateRun {
  json started;                // the first CALIBRATE reply
  std::vector<json> progress;  // progress events of the operation, in order
  std::optional<json> finished;
  std::optional<json> reply;  // the final CALIBRATE or ERROR
};

// Reads until the final reply to `id` (none for id < 0: a watcher) and the
// finished event arrive.
inline void follow(Connection& c, int id, CalibrateRun& run,
                   std::chrono::milliseconds timeout = 90s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout * kSlowdown;
  while (std::chrono::steady_clock::now() < deadline && !(run.finished && (run.reply || id < 0))) {
    auto msg = c.next(std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now()));
    if (!msg) break;
    if ((*msg)["class"] == "EVENT") {
      if ((*msg)["event"] == "progress") run.progress.push_back(*msg);
      if ((*msg)["event"] == "finished") run.finished = *msg;
    } else if ((*msg)["id"] == id) {
      run.reply = *msg;
    }
  }
}

// Runs calibrate to a successful final reply (fatal test failures otherwise), handed
// back in `reply` when given.
inline void calibrateToTheEnd(Connection& c, const DaemonProcess& d, json* reply = nullptr) {
  auto started = c.call(calibrateRequest(1));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  CalibrateRun run;
  follow(c, 1, run);
  ASSERT_TRUE(run.reply) << d.log();
  ASSERT_EQ((*run.reply)["class"], "CALIBRATE") << run.reply->dump();
  if (reply) *reply = *run.reply;
}

}  // namespace procam::itest
