// The device manager with the real aravis driver against Aravis' fake GigE Vision
// camera on loopback (arv-fake-gv-camera-0.8 -i 127.0.0.1, started by the test;
// HARDWARE-TESTING.md): the camera gets no frame reader and has no udev event, so only
// the liveness checks can notice that it died (the server killed, as a camera losing
// power) and that it came back (a new server).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <variant>

#include "camera/plugin/camera_plugin.hpp"
#include "device_manager.hpp"
#include "unit/camera/fake_gige.hpp"

namespace procam::daemon {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

class AravisLiveness : public ::testing::Test {
 protected:
  void SetUp() override {
    binary_ = test::findOnPath(test::kFakeBinary);
    if (binary_.empty())
      GTEST_SKIP() << test::kFakeBinary << " is not installed (Debian package aravis-tools)";
    server_ = std::make_unique<test::FakeGigE>(binary_);
    ASSERT_TRUE(server_->running()) << "could not start " << binary_;
    registry_.add(plugins::Driver{&camera::plugin::kAravisFactory, "static", nullptr});
    loop_ = std::move(*EventLoop::create());
  }
  void TearDown() override {
    manager_.reset();
    devices_.closeAll();
  }

  // Runs the loop until `pred` holds (checked every 10 ms); false on timeout. Records
  // the longest the loop went without running its 10 ms timer.
  template <class F>
  bool runUntil(F pred, std::chrono::milliseconds timeout) {
    bool met = false;
    auto last = Clock::now();
    auto check = loop_->addTimer(10ms, true, [&] {
      const auto now = Clock::now();
      longest_stall_ = std::max(longest_stall_, std::chrono::duration<double>(now - last).count());
      last = now;
      if (pred()) {
        met = true;
        loop_->stop();
      }
    });
    auto limit = loop_->addTimer(timeout, false, [&] { loop_->stop(); });
    loop_->run();
    loop_->removeTimer(*check);
    if (met) loop_->removeTimer(*limit);
    return met;
  }

  std::string state() {
    const DeviceEntry* e = devices_.find("gige");
    return e ? e->state() : "absent";
  }

  std::string binary_;
  std::unique_ptr<test::FakeGigE> server_;
  plugins::DriverRegistry registry_;
  DeviceSet devices_;
  std::unique_ptr<EventLoop> loop_;
  std::unique_ptr<DeviceManager> manager_;
  double longest_stall_ = 0;
};

TEST_F(AravisLiveness, KilledCameraIsLostWithinThreeSecondsAndReopenedWhenItIsBack) {
  plugins::DeviceDescription desc;
  desc.family = PROCAM_FAMILY_CAMERA;
  desc.name = "gige";
  desc.subsystem = "config";
  const DeviceOptions options = {
      {"id", test::kLoopback}, {"width", "640"}, {"height", "480"}, {"pixel_format", "Mono8"}};
  // As procamd's configuration opens it; the server needs a moment to bind its socket.
  for (int i = 0; i < 100; ++i) {
    devices_.open(registry_, desc, "aravis", options);
    if (devices_.find("gige")->usable()) break;
    devices_.close("gige");
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_EQ(state(), "open") << devices_.find("gige")->error;

  std::vector<std::string> warnings;
  manager_ = std::make_unique<DeviceManager>(
      *loop_, registry_, devices_, [](const std::string&, nlohmann::json) {},
      [&](const std::string& m) { warnings.push_back(m); });
  int frames = 0;
  manager_->onReading([&](const DeviceEntry&, const Reading& r) {
    if (std::holds_alternative<CameraFrame>(r)) ++frames;
  });
  manager_->start({.udev = false});  // procamd's presence interval: 1 s
  // Nobody reads it: only the liveness captures (about one a second) bring frames.
  ASSERT_TRUE(runUntil([&] { return frames >= 2; }, 4s)) << frames << " frame(s)";
  EXPECT_LE(frames, 4);

  server_->kill();
  const auto killed = Clock::now();
  longest_stall_ = 0;
  ASSERT_TRUE(runUntil([&] { return state() == "lost"; }, 3s))
      << "still " << state() << " 3 s after the kill";
  const double to_lost = secondsSince(killed);
  std::printf("aravis: lost %.2f s after the kill (%s)\n", to_lost,
              devices_.find("gige")->error.c_str());
  RecordProperty("seconds_to_lost", std::to_string(to_lost));
  EXPECT_NE(devices_.find("gige")->error.find("127.0.0.1"), std::string::npos)
      << devices_.find("gige")->error;
  ASSERT_FALSE(warnings.empty());

  // Back at once: the first reopen (1 s after the loss) finds it.
  server_ = std::make_unique<test::FakeGigE>(binary_);
  ASSERT_TRUE(server_->running());
  const auto restarted = Clock::now();
  ASSERT_TRUE(runUntil([&] { return state() == "open"; }, 10s))
      << "still " << state() << ": " << devices_.find("gige")->error;
  const double to_open = secondsSince(restarted);
  std::printf("aravis: open again %.2f s after the new server started\n", to_open);
  RecordProperty("seconds_to_reopen", std::to_string(to_open));
  // The release of the dead camera and the reopen ran off the loop.
  std::printf("aravis: longest loop stall %.3f s\n", longest_stall_);
  EXPECT_LT(longest_stall_, 0.5);
  // And it is checked again: frames from the new server.
  const int before = frames;
  ASSERT_TRUE(runUntil([&] { return frames > before; }, 3s));
}

}  // namespace
}  // namespace procam::daemon
