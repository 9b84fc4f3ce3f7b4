// procamd with Aravis' fake GigE Vision camera (arv-fake-gv-camera-0.8 on loopback,
// started by each test; skipped without aravis-tools). The fake server binds the GVCP
// port of 127.0.0.1, so these tests hold ctest's "aravis-fake-gige" lock: one at a
// time, and never beside the driver's own live tests.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "camera_requests.hpp"
#include "daemon_harness.hpp"
#include "unit/camera/fake_gige.hpp"

namespace procam::itest {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// A fake camera server and procamd configured with it as camera "gige" (640x480 Mono8).
class AravisDaemon : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string binary = test::findOnPath(test::kFakeBinary);
    if (binary.empty()) GTEST_SKIP() << test::kFakeBinary << " is not installed (aravis-tools)";
    camera_ = std::make_unique<test::FakeGigE>(binary);
    ASSERT_TRUE(camera_->running());
    dir_.write("procamd.toml",
               "[[camera]]\nname = \"gige\"\ndriver = \"aravis\"\n[camera.options]\n"
               "id = \"127.0.0.1\"\nwidth = \"640\"\nheight = \"480\"\n"
               "pixel_format = \"Mono8\"\n");
    daemon_ = std::make_unique<DaemonProcess>(
        dir_, DaemonProcess::Launch{{"--config", dir_.file("procamd.toml")}, {}, -1, true});
    ASSERT_TRUE(daemon_->started()) << daemon_->log();
    c_ = std::make_unique<Connection>(daemon_->socketPath());
  }

  TempDir dir_;
  std::unique_ptr<test::FakeGigE> camera_;
  std::unique_ptr<DaemonProcess> daemon_;
  std::unique_ptr<Connection> c_;
};

// A stop within 2 s although the Aravis camera died and libaravis blocks
// releasing it.
TEST_F(AravisDaemon, StopsWithinTwoSecondsWhenItsCameraDied) {
  auto& c = *c_;
  auto& d = *daemon_;
  auto& camera = camera_;
  auto open = [&] {
    auto devices = c.call({{"cmd", "devices"}});
    if (!devices) return false;
    for (const auto& dev : (*devices)["devices"]) {
      if (dev["name"] == "gige") return dev["state"] == "open";
    }
    return false;
  };
  // The fake server needs a moment to bind; procamd retries the open.
  ASSERT_TRUE(eventually(open, 15s)) << d.log();
  camera->kill();
  std::this_thread::sleep_for(300ms);
  const auto stop = Clock::now();
  d.signal(SIGTERM);
  auto status = d.wait(5s);
  const double took = secondsSince(stop);
  std::printf("stop: %.2f s after SIGTERM with a dead Aravis camera\n", took);
  ASSERT_TRUE(status) << "still running 5 s after SIGTERM";
  EXPECT_EQ(*status, 0);
  EXPECT_LT(took, 2.0);
}

TEST_F(AravisDaemon, SnapshotExposureIsSetAndReadBack) {
  auto& c = *c_;
  auto& d = *daemon_;
  // The fake server needs a moment to bind; procamd retries the open.
  std::optional<json> shot;
  ASSERT_TRUE(eventually(
      [&] {
        shot = c.call({{"cmd", "snapshot"}, {"camera", "gige"}, {"exposure_s", 0.004}}, 15s);
        return shot && (*shot)["class"] == "SNAPSHOT";
      },
      30s))
      << (shot ? shot->dump() : "no reply") << d.log();
  EXPECT_EQ((*shot)["width"], 640);
  EXPECT_EQ((*shot)["height"], 480);
  EXPECT_EQ((*shot)["format"], "gray8");
  // Read back from the camera's ExposureTime register (µs, a float).
  EXPECT_NEAR(shot->value("exposure_s", 0.0), 0.004, 1e-6) << shot->dump();
  EXPECT_EQ((*shot)["gain_unit"], "dB") << shot->dump();
  EXPECT_TRUE((*shot)["gain"].is_number()) << shot->dump();
  const cv::Mat img = cv::imread(shot->value("path", ""), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(img.cols, 640);
  const Levels counted = countLevels(img);
  EXPECT_NEAR(shot->value("saturated_pct", -1.0), counted.saturated, 1e-9);
  EXPECT_NEAR(shot->value("underexposed_pct", -1.0), counted.underexposed, 1e-9);
  std::printf("aravis fake camera: exposure %.6f s, gain %.2f dB, %.2f %% saturated\n",
              shot->value("exposure_s", 0.0), shot->value("gain", 0.0),
              shot->value("saturated_pct", 0.0));
}

TEST_F(AravisDaemon, CalibrateCameraWithoutABoardEndsWithItsCounts) {
  auto& c = *c_;
  auto& d = *daemon_;
  std::optional<json> r;
  ASSERT_TRUE(eventually(
      [&] {
        r = c.call({{"cmd", "calibrate-camera"},
                    {"id", 1},
                    {"camera", "gige"},
                    {"board", kCameraBoard},
                    {"interval_s", 0.05},
                    {"timeout_s", 2}});
        return r && r->value("state", "") == "started";
      },
      30s))
      << (r ? r->dump() : "no reply") << d.log();
  std::vector<json> views;
  auto done = finalReply(c, 1, views, 30s);
  ASSERT_TRUE(done) << d.log();
  EXPECT_EQ((*done)["code"], "failed") << done->dump();
  const std::string msg = done->value("message", "");
  EXPECT_NE(msg.find("0 board view(s) kept"), std::string::npos) << msg;
  EXPECT_NE(msg.find("board not found"), std::string::npos) << msg;
  ASSERT_FALSE(views.empty());
  EXPECT_EQ(views.back()["views"], 0);
  EXPECT_EQ(views.back()["rejections"]["board not found"], views.back()["frames"]);
  // Nothing was written.
  EXPECT_FALSE(std::filesystem::exists(dir_.file("state/rig.json")));
}

}  // namespace
}  // namespace procam::itest
