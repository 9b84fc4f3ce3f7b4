// Projector–camera synchronisation on the virtual rig, over the socket only:
// scenes whose cameras see the projector 0.1 s late (latency_s); `latency`
// measures it, and `calibrate` with settle_frames "auto" waits for it.
#include <gtest/gtest.h>

#include <cmath>

#include "daemon_harness.hpp"
#include "truth_rig_file.hpp"
#include "unit/calibration/rig_capture.hpp"

namespace procam::itest {
namespace {

// The scenes' truth (s): 0.1 s, and kSlowdown times that under AddressSanitizer
// so that the slower captures still sample it finer than it is long. Every
// time below scales with it.
constexpr double kLatency = 0.1 * kSlowdown;
constexpr double kRefreshHz = 60;  // the mock output's
// kLatency in output frames: 6 (48 under AddressSanitizer).
constexpr int kLatencyFrames = static_cast<int>(kLatency * kRefreshHz + 0.5);

// Adds `latency_s` to every camera of a scene text.
std::string withLatency(std::string text, double latency_s) {
  EXPECT_TRUE(procam::testing::edit(
      text, "[[cameras]]\n", "[[cameras]]\nlatency_s = " + std::to_string(latency_s) + "\n"));
  return text;
}

// handheld with its camera at 80x60 (an eighth): quick ray-cast captures.
std::string handheldScene(const TempDir& dir, double latency_s) {
  std::string t = procam::testing::sceneText("handheld");
  EXPECT_TRUE(procam::testing::scaleDevice(t, 640, 480, 0.125));
  dir.write("handheld_latency.toml", withLatency(t, latency_s));
  return dir.file("handheld_latency.toml");
}

// A camera entry of a reply: within one frame period of the truth, and consistent.
// `max_period`: the frame period the scene's ray casting must beat for the
// check to mean something (with a capture every 0.2 s anything from 0 to 0.2 s
// would pass for 0.1 s).
void checkCamera(const json& cam, double truth, int margin_frames, double max_period) {
  const double median = cam["latency_s"]["median"].get<double>();
  const double period = cam["frame_period_s"].get<double>();
  EXPECT_GT(period, 0);
  EXPECT_LT(period, max_period) << cam.dump();
  EXPECT_LE(std::abs(median - truth), period) << cam.dump();
  // One switch's error is within the frames around it: the longest interval between
  // two captures (a loaded machine delays some).
  const double longest = cam["frame_period_max_s"].get<double>();
  EXPECT_GE(longest, period);
  for (const auto& s : cam["samples"]) EXPECT_LE(std::abs(s.get<double>() - truth), longest);
  EXPECT_EQ(cam["settle_frames"],
            static_cast<int>(std::ceil(median * kRefreshHz - 1e-9)) + margin_frames);
  EXPECT_GT(cam["contrast"].get<double>(), 10) << cam.dump();
  std::printf("latency truth %.3f s: measured %.4f s (spread %.4f s), frame period %.4f s\n", truth,
              median, cam["latency_s"]["spread"].get<double>(), period);
}

TEST(SimLatency, MeasuredWithinOneFramePeriod) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", handheldScene(dir, kLatency)}, {}});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Bad arguments and devices that are not there.
  auto r = c.call({{"cmd", "latency"}, {"id", 1}, {"repeats", 0}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "bad-argument") << r->dump();
  r = c.call({{"cmd", "latency"}, {"id", 2}, {"cameras", {"nope"}}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable") << r->dump();
  EXPECT_NE((*r)["message"].get<std::string>().find("'nope'"), std::string::npos);
  r = c.call({{"cmd", "latency"}, {"id", 3}, {"output", "cam"}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable") << r->dump();

  const auto measurement = [](int id) {
    return json{{"cmd", "latency"},
                {"id", id},
                {"repeats", 3},
                {"margin_frames", 2},
                {"timeout_s", 1.0 * kSlowdown}};
  };
  r = c.call(measurement(4));
  ASSERT_TRUE(r);
  ASSERT_EQ((*r)["class"], "LATENCY") << r->dump();
  EXPECT_EQ((*r)["state"], "started");
  EXPECT_EQ((*r)["output"], "proj");
  EXPECT_EQ((*r)["cameras"], json({"cam"}));
  // One at a time, as with calibrate.
  Connection other(d.socketPath());
  auto busy = other.call({{"cmd", "latency"}, {"id", 5}});
  ASSERT_TRUE(busy);
  EXPECT_EQ((*busy)["code"], "busy") << busy->dump();

  auto done = finalReply(c, 4, 60s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "LATENCY") << done->dump();
  // A capture every 0.05 s or more says little of 0.1 s (checkCamera): a loaded machine
  // delays the virtual camera's ray casting now and then, so measure again, twice at most.
  for (int id = 6; id < 8 && (*done)["cameras"].size() == 1u &&
                   (*done)["cameras"][0].value("frame_period_s", 1.0) >= 0.5 * kLatency;
       ++id) {
    std::printf("frame period %.4f s: measured again\n",
                (*done)["cameras"][0].value("frame_period_s", 1.0));
    r = c.call(measurement(id));
    ASSERT_TRUE(r);
    ASSERT_EQ((*r)["class"], "LATENCY") << r->dump();
    done = finalReply(c, id, 60s);
    ASSERT_TRUE(done) << d.log();
    ASSERT_EQ((*done)["class"], "LATENCY") << done->dump();
  }
  EXPECT_EQ((*done)["state"], "done");
  EXPECT_EQ((*done)["refresh_hz"], kRefreshHz);
  ASSERT_EQ((*done)["cameras"].size(), 1u);
  const json& cam = (*done)["cameras"][0];
  EXPECT_EQ(cam["name"], "cam");
  EXPECT_EQ(cam["samples"].size(), 6u);  // two switches per repeat
  checkCamera(cam, kLatency, 2, 0.5 * kLatency);
  EXPECT_EQ((*done)["latency_s"], cam["latency_s"]["median"]);
  EXPECT_EQ((*done)["settle_frames"], cam["settle_frames"]);
  // 0.1 s at 60 Hz is 6 frames; the estimate is within a frame period of it.
  EXPECT_GE((*done)["settle_frames"].get<int>(), kLatencyFrames);
  EXPECT_LE((*done)["settle_frames"].get<int>(), kLatencyFrames + 2 + 2);
}

TEST(SimLatency, NoLatencyMeasuresNone) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", handheldScene(dir, 0.0)}, {}});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto r = c.call({{"cmd", "latency"}, {"id", 1}, {"repeats", 1}, {"timeout_s", 0.3 * kSlowdown}});
  ASSERT_TRUE(r);
  ASSERT_EQ((*r)["class"], "LATENCY") << r->dump();
  auto done = finalReply(c, 1, 30s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "LATENCY") << done->dump();
  // The estimate lies within one frame period after the truth; a period under
  // kLatency keeps "no latency" apart from the 0.1 s of the other scenes while
  // leaving room for a loaded machine's slower ray casting.
  checkCamera((*done)["cameras"][0], 0.0, 1, kLatency);
}

// corner_stereo at half resolution (as in test_sim_calibrate.cpp), both
// cameras 0.1 s late.
std::string cornerScene(const TempDir& dir) {
  std::string t = procam::testing::sceneText("corner_stereo");
  EXPECT_TRUE(procam::testing::scaleDevice(t, 1280, 800, 0.5));  // proj
  EXPECT_TRUE(procam::testing::scaleDevice(t, 1024, 768, 0.5));  // cam_left
  EXPECT_TRUE(procam::testing::scaleDevice(t, 1024, 768, 0.5));  // cam_right
  dir.write("corner_latency.toml", withLatency(t, kLatency));
  return dir.file("corner_latency.toml");
}

// The projector centre from a calibrate reply, and its distance to the truth (mm).
double positionErrorMm(const json& reply, const std::string& scene_file) {
  auto scene = sim::Scene::load(scene_file);
  EXPECT_TRUE(scene) << scene.error().message;
  const Vec3 truth = scene->at(0).projectors.at(0).model.pose.center();
  const Vec3 p(reply["position"][0], reply["position"][1], reply["position"][2]);
  return (p - truth).norm() * 1000;
}

TEST(SimLatency, CalibrateSettlesByTheMeasuredLatency) {
  TempDir dir;
  const std::string scene = cornerScene(dir);
  // One black/white cycle per camera keeps the measurement short.
  dir.write("procamd.toml", "[calibration]\nlatency_repeats = 1\nlatency_timeout_s = " +
                                std::to_string(1.0 * kSlowdown) + "\n");
  DaemonProcess d(
      dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--sim", scene, "--rig",
                                  truthRigFile(dir, scene, TruthParts::kCamerasOnly)},
                                 {}});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  const json request = {
      {"cmd", "calibrate"}, {"mode", "gray+phase"}, {"phase_steps", 3}, {"grid", 8}};

  // Without a wait the first camera captures every pattern 0.1 s too early: it
  // sees the previous one, and the decoded codes are wrong.
  json early = request;
  early["id"] = 1;
  early["settle_frames"] = 0;
  auto r = c.call(early);
  ASSERT_TRUE(r);
  ASSERT_EQ((*r)["class"], "CALIBRATE") << r->dump();
  EXPECT_EQ((*r)["settle_frames"], 0);
  auto bad = finalReply(c, 1, 120s);
  ASSERT_TRUE(bad) << d.log();
  if ((*bad)["class"] == "CALIBRATE") {
    // Solved from wrong codes: far from the truth (a right run is within 2 mm).
    EXPECT_GT(positionErrorMm(*bad, scene), 20.0) << bad->dump();
    std::printf("settle 0: position error %.1f mm\n", positionErrorMm(*bad, scene));
  } else {
    EXPECT_EQ((*bad)["class"], "ERROR");
    std::printf("settle 0: %s\n", (*bad)["message"].get<std::string>().c_str());
  }

  json automatic = request;
  automatic["id"] = 2;
  automatic["settle_frames"] = "auto";
  r = c.call(automatic);
  ASSERT_TRUE(r);
  ASSERT_EQ((*r)["class"], "CALIBRATE") << r->dump();
  EXPECT_EQ((*r)["settle_frames"], "auto");
  auto good = finalReply(c, 2, 180s);
  ASSERT_TRUE(good) << d.log();
  ASSERT_EQ((*good)["class"], "CALIBRATE") << good->dump();
  const json& latency = (*good)["latency"];
  ASSERT_EQ(latency["cameras"].size(), 2u) << good->dump();
  // Half-resolution cameras ray-cast a frame in 0.1 to 0.2 s on two idle
  // cores and up to 0.45 s beside another ray-casting test: the measurement's
  // resolution is MeasuredWithinOneFramePeriod's to show; here it must stay
  // within its one period and give a settle that calibrates right (below).
  for (const auto& cam : latency["cameras"]) checkCamera(cam, kLatency, 1, 1.0 * kSlowdown);
  EXPECT_EQ((*good)["settle_frames"], latency["settle_frames"]);
  EXPECT_GE((*good)["settle_frames"].get<int>(), kLatencyFrames);
  // The accuracy of test_sim_calibrate.cpp on the scene without latency.
  const double position_mm = positionErrorMm(*good, scene);
  EXPECT_LT(position_mm, 2.0);
  EXPECT_LE((*good)["reprojection_rms_px"].get<double>(), 0.15);
  std::printf("settle auto (%d frames): position error %.2f mm, RMS %.3f px\n",
              (*good)["settle_frames"].get<int>(), position_mm,
              (*good)["reprojection_rms_px"].get<double>());
}

}  // namespace
}  // namespace procam::itest
