// calibrate-camera over the socket: a camera's intrinsics from a board moved before
// it. On the virtual rig (scene camera_board: the camera circles a checkerboard on a
// wall, the relative motion of a board carried before a fixed camera) the result is
// judged against the scene's camera; on Aravis' fake GigE Vision camera, which shows
// no board, the run ends with the counts of what it saw.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "camera_requests.hpp"
#include "daemon_harness.hpp"
#include "sim/scene_library.hpp"

namespace procam::itest {
namespace {

TEST(CalibrateCamera, VirtualRigIntrinsicsWithinTheirTolerances) {
  auto scene = sim::resolveScene("camera_board");
  ASSERT_TRUE(scene) << scene.error().message;
  const auto& truth = scene->cameras().at(0);
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "camera_board"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  auto r = c.call({{"cmd", "calibrate-camera"}, {"id", 1}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "bad-argument") << r->dump();  // no board
  r = c.call({{"cmd", "calibrate-camera"}, {"id", 2}, {"board", kCameraBoard}, {"camera", "nope"}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable") << r->dump();
  r = c.call({{"cmd", "calibrate-camera"}, {"id", 3}, {"action", "finish"}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "not-found") << r->dump();

  // The targets: 12 views covering 40 % of the image (the scene's trajectory reaches about
  // half wherever the slower sanitizer captures sample it), RMS under 0.5 px.
  r = c.call({{"cmd", "calibrate-camera"},
              {"id", 4},
              {"camera", "cam"},
              {"board", kCameraBoard},
              {"views", 12},
              {"coverage", 0.4},
              {"rms_px", 0.5},
              {"interval_s", 0.1},
              {"timeout_s", 90 * kSlowdown}});
  ASSERT_TRUE(r);
  ASSERT_EQ((*r)["state"], "started") << r->dump();
  // Busy while it runs.
  Connection other(d.socketPath());
  auto busy = other.call({{"cmd", "snapshot"}, {"id", 9}});
  ASSERT_TRUE(busy);
  EXPECT_EQ((*busy)["code"], "busy") << busy->dump();

  std::vector<json> views;
  auto done = finalReply(c, 4, views, std::chrono::seconds(120 * kSlowdown));
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["state"], "done") << done->dump();
  EXPECT_EQ((*done)["stopped"], "targets") << done->dump();
  const json& K = (*done)["camera"]["K"];
  const double fx = K[0], fy = K[4], cx = K[2], cy = K[5];
  std::printf(
      "calibrate-camera: %d views of %d frames, coverage %.2f, RMS %.3f px; fx %.2f (truth "
      "%.2f, %.3f %%), fy %.2f (truth %.2f, %.3f %%), cx %.2f (%+.2f px), cy %.2f (%+.2f px)\n",
      done->value("views", 0), done->value("frames", 0), done->value("coverage", 0.0),
      done->value("reprojection_rms_px", 0.0), fx, truth.K.fx,
      100 * std::abs(fx - truth.K.fx) / truth.K.fx, fy, truth.K.fy,
      100 * std::abs(fy - truth.K.fy) / truth.K.fy, cx, cx - truth.K.cx, cy, cy - truth.K.cy);
  // Zhang's method on a dozen well-spread views of 54 corners: a focal length within
  // 0.3 % and the principal point within 1 px.
  EXPECT_LE(std::abs(fx - truth.K.fx), 0.003 * truth.K.fx);
  EXPECT_LE(std::abs(fy - truth.K.fy), 0.003 * truth.K.fy);
  EXPECT_LE(std::abs(cx - truth.K.cx), 1.0);
  EXPECT_LE(std::abs(cy - truth.K.cy), 1.0);
  EXPECT_GE(done->value("views", 0), 12);
  EXPECT_GE(done->value("coverage", 0.0), 0.4);
  EXPECT_LE(done->value("reprojection_rms_px", 1.0), 0.5);
  EXPECT_FALSE((*done)["camera"]["pose_known"].get<bool>());

  // Progress after every frame: views and coverage never fall; the RMS appears
  // once four views are kept.
  ASSERT_FALSE(views.empty());
  int last_views = 0;
  double last_coverage = 0;
  bool rms_seen = false;
  for (const auto& v : views) {
    EXPECT_GE(v.value("views", -1), last_views);
    EXPECT_GE(v.value("coverage", -1.0), last_coverage);
    last_views = v.value("views", 0);
    last_coverage = v.value("coverage", 0.0);
    if (v["rms_px"].is_number()) {
      rms_seen = true;
      EXPECT_GE(last_views, 4);
    }
  }
  EXPECT_TRUE(rms_seen);

  // Stored in rig.json, without a pose: calibrate refuses the camera until it has one.
  std::ifstream in((*done)["path"].get<std::string>());
  const json rig = json::parse(in, nullptr, false);
  ASSERT_TRUE(rig.is_object());
  ASSERT_EQ(rig["cameras"].size(), 1u);
  EXPECT_EQ(rig["cameras"][0]["name"], "cam");
  EXPECT_EQ(rig["cameras"][0]["pose_known"], false);
  EXPECT_NEAR(rig["cameras"][0]["K"][0].get<double>(), fx, 1e-9);
  r = c.call({{"cmd", "calibrate"}, {"id", 5}, {"cameras", {"cam"}}, {"plane", {0, 1, 0, -1.6}}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable") << r->dump();
  EXPECT_NE(r->value("message", "").find("no pose"), std::string::npos) << r->dump();
}

TEST(CalibrateCamera, FinishSolvesWithTheViewsKeptSoFar) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "camera_board"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(c.call({{"cmd", "watch"}, {"id", 0}}));
  // Targets it cannot reach: it runs until asked to finish.
  auto r = c.call({{"cmd", "calibrate-camera"},
                   {"id", 1},
                   {"board", kCameraBoard},
                   {"views", 100},
                   {"interval_s", 0.1},
                   {"timeout_s", 300 * kSlowdown}});
  ASSERT_TRUE(r);
  ASSERT_EQ((*r)["state"], "started") << r->dump();
  std::vector<json> views;
  int kept = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60 * kSlowdown);
  while (kept < 5 && std::chrono::steady_clock::now() < end) {
    auto m = c.next(std::chrono::seconds(10 * kSlowdown));
    ASSERT_TRUE(m) << d.log();
    if ((*m)["class"] == "EVENT" && (*m)["event"] == "views") kept = m->value("views", 0);
  }
  ASSERT_GE(kept, 5);
  Connection other(d.socketPath());
  auto fin = other.call({{"cmd", "calibrate-camera"}, {"id", 2}, {"action", "finish"}});
  ASSERT_TRUE(fin);
  EXPECT_EQ((*fin)["class"], "CALIBRATE-CAMERA") << fin->dump();
  EXPECT_EQ((*fin)["finishing"].size(), 1u);
  auto done = finalReply(c, 1, views, std::chrono::seconds(30 * kSlowdown));
  ASSERT_TRUE(done) << d.log();
  EXPECT_EQ((*done)["state"], "done") << done->dump();
  EXPECT_EQ((*done)["stopped"], "finish");
  EXPECT_GE(done->value("views", 0), 5);
}

}  // namespace
}  // namespace procam::itest
