// A replayed recording through the running daemon (drivers/camera/README.md,
// "replay"): a [[camera]] with driver "replay" in procamd.toml is opened, its
// frames are read as the recording's timerfd makes them due, `devices` counts
// them and measures their rate, and at the end of the recording the camera
// ends (not reopened: the recording is not played again) while the daemon
// keeps answering.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

constexpr int kFrames = 120;
constexpr double kFps = 20.0;  // 6 s of recording

// kFrames tiny gray PNGs and index.csv at kFps, with an arbitrary time origin.
void writeRecording(const TempDir& dir) {
  std::ostringstream index;
  index << "file,timestamp\n";
  for (int i = 0; i < kFrames; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame%03d.png", i);
    cv::Mat img(12, 16, CV_8UC1, cv::Scalar(i * 3));
    ASSERT_TRUE(cv::imwrite(dir.file(name), img));
    index << name << "," << std::fixed << 5000.0 + i / kFps << "\n";
  }
  dir.write("index.csv", index.str());
}

std::optional<json> camera(Connection& c) {
  auto devices = c.call({{"cmd", "devices"}});
  if (!devices) return std::nullopt;
  for (const auto& d : (*devices)["devices"]) {
    if (d["name"] == "rec") return d;
  }
  return std::nullopt;
}

TEST(ReplayDaemon, FramesArriveAtTheRecordedRateThenTheCameraEnds) {
  TempDir recording;
  writeRecording(recording);
  TempDir dir;
  dir.write("procamd.toml",
            "[[camera]]\nname = \"rec\"\ndriver = \"replay\"\n[camera.options]\ndir = \"" +
                recording.path() + "\"\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml")}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection watcher(d.socketPath());
  Connection c(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  auto first = camera(c);
  ASSERT_TRUE(first) << d.log();
  EXPECT_EQ((*first)["state"], "open") << first->dump();
  EXPECT_EQ((*first)["driver"], "replay");
  EXPECT_EQ((*first)["family"], "camera");

  // A second into the recording plus a full rate window (2 s), so that frames
  // due before the loop ran are out of it: the measured rate and the count over
  // one more second both match the recording's 20 fps.
  ASSERT_TRUE(eventually(
      [&] {
        auto cam = camera(c);
        return cam && cam->value("frames", 0) >= 60;
      },
      8s))
      << d.log();
  auto a = camera(c);
  const auto ta = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(1s);
  auto b = camera(c);
  const auto tb = std::chrono::steady_clock::now();
  ASSERT_TRUE(a && b);
  const double elapsed = std::chrono::duration<double>(tb - ta).count();
  const int frames = (*b)["frames"].get<int>() - (*a)["frames"].get<int>();
  ASSERT_LT((*b)["frames"].get<int>(), kFrames) << "the recording ended too soon: " << b->dump();
  // Within a frame at each end of the interval, plus one for the replies' delay.
  EXPECT_NEAR(frames, kFps * elapsed, 3.0) << a->dump() << "\n" << b->dump();
  EXPECT_NEAR((*b)["rate_hz"].get<double>(), kFps, 0.1 * kFps) << b->dump();
  EXPECT_NEAR((*a)["rate_hz"].get<double>(), kFps, 0.1 * kFps) << a->dump();
  std::printf("replay: %d frames in %.3f s (%.2f expected); measured rate %.2f, %.2f Hz\n", frames,
              elapsed, kFps * elapsed, (*a)["rate_hz"].get<double>(),
              (*b)["rate_hz"].get<double>());
  // The frames' timestamps keep the recorded spacing on the daemon's clock.
  const double dts = (*b)["last_timestamp"].get<double>() - (*a)["last_timestamp"].get<double>();
  EXPECT_NEAR(dts, frames / kFps, 1e-6) << a->dump() << "\n" << b->dump();

  // The end of a non-looping recording: ended, and the daemon still answers.
  std::optional<json> removed;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!removed && std::chrono::steady_clock::now() < deadline) {
    auto line = watcher.next(1s);
    if (line && (*line)["class"] == "EVENT" && (*line)["event"] == "device-removed" &&
        (*line)["name"] == "rec") {
      removed = line;
    }
  }
  ASSERT_TRUE(removed) << d.log();
  EXPECT_EQ((*removed)["state"], "ended");
  EXPECT_NE((*removed)["error"].get<std::string>().find("end of the recording"), std::string::npos)
      << removed->dump();
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["class"], "STATUS");
  // Every frame was read once, and past the first reopen back-off of a lost
  // device (1 s) and the rate window (2 s) the camera is still ended: the
  // recording did not start over, and no frame arrives.
  std::this_thread::sleep_for(2500ms);
  auto after = camera(c);
  ASSERT_TRUE(after);
  EXPECT_EQ((*after)["state"], "ended") << after->dump();
  EXPECT_EQ((*after)["frames"].get<int>(), kFrames) << after->dump();
  EXPECT_EQ((*after)["rate_hz"].get<double>(), 0.0) << after->dump();

  // reload opens the configured camera again: the recording plays from the start.
  auto reloaded = c.call({{"cmd", "reload"}});
  ASSERT_TRUE(reloaded);
  EXPECT_EQ((*reloaded)["class"], "RELOAD") << reloaded->dump();
  ASSERT_TRUE(eventually(
      [&] {
        auto cam = camera(c);
        return cam && (*cam)["state"] == "open" &&
               (*cam)["last_timestamp"].get<double>() > (*after)["last_timestamp"].get<double>();
      },
      5s))
      << d.log();
}

}  // namespace
}  // namespace procam::itest
