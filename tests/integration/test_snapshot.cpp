// `snapshot` end to end: the daemon captures one frame of a camera, writes it as
// PNG to its state directory and reports exposure, gain and clipped pixels;
// procamctl copies the file where the installer asked. On the virtual rig
// (through procamctl), a replayed recording (every pixel known) and Aravis' fake
// GigE Vision camera (exposure set and read back from the camera). Also the other
// camera requests an installer runs through procamctl: latency, and calibrate's
// list arguments.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "camera_requests.hpp"
#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

TEST(Snapshot, VirtualRigFrameThroughProcamctl) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "handheld"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(c.call({{"cmd", "pattern"}, {"name", "white"}}));
  int status = -1;
  const std::string white_png = dir.file("white.png");
  const json white = ctlJson(d, {"snapshot", "cam", "-o", white_png}, status);
  ASSERT_EQ(status, 0) << white.dump();
  EXPECT_EQ(white["class"], "SNAPSHOT");
  EXPECT_EQ(white["camera"], "cam");
  EXPECT_EQ(white["format"], "gray8");
  // The virtual camera's exposure is a factor, not a time; its gain is 1 (0 dB).
  EXPECT_TRUE(white["exposure_s"].is_null()) << white.dump();
  EXPECT_EQ(white["gain_unit"], "dB");
  EXPECT_NEAR(white.value("gain", -1.0), 0.0, 1e-9);
  // The copy procamctl made is the daemon's file, and the levels are the file's.
  const cv::Mat img = cv::imread(white_png, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, white.value("width", 0));
  EXPECT_EQ(img.rows, white.value("height", 0));
  EXPECT_EQ(std::filesystem::file_size(white_png),
            std::filesystem::file_size(white.value("path", "")));
  EXPECT_EQ(white.value("path", ""), dir.file("state/snapshots/cam.png"));
  const Levels counted = countLevels(img);
  EXPECT_NEAR(white.value("saturated_pct", -1.0), counted.saturated, 1e-9);
  EXPECT_NEAR(white.value("underexposed_pct", -1.0), counted.underexposed, 1e-9);
  EXPECT_NEAR(white.value("mean_pct", -1.0), 100.0 * cv::mean(img)[0] / 255.0, 1e-6);

  // The projector lit white, then black: the mean follows what the camera sees.
  ASSERT_TRUE(c.call({{"cmd", "pattern"}, {"name", "black"}}));
  const json black = ctlJson(d, {"snapshot", "-o", dir.file("black.png")}, status);
  ASSERT_EQ(status, 0) << black.dump();
  EXPECT_EQ(black["camera"], "cam");  // the first camera by default
  std::printf("snapshot: white %.1f %% mean (%.2f %% saturated), black %.1f %% mean\n",
              white.value("mean_pct", 0.0), white.value("saturated_pct", 0.0),
              black.value("mean_pct", 0.0));
  EXPECT_GT(white.value("mean_pct", 0.0), black.value("mean_pct", 0.0) + 5.0);
  EXPECT_GT(black.value("underexposed_pct", 0.0), white.value("underexposed_pct", 0.0));

  // Clear errors: no such camera, a fixed exposure, an exposure out of range.
  json bad = ctlJson(d, {"snapshot", "nocam"}, status);
  EXPECT_EQ(status, 5) << bad.dump();
  bad = ctlJson(d, {"snapshot", "cam", "--exposure", "0.01"}, status);
  EXPECT_EQ(status, 5) << bad.dump();
  EXPECT_NE(bad.value("message", "").find("exposure"), std::string::npos) << bad.dump();
  auto raw = c.call({{"cmd", "snapshot"}, {"exposure_s", 100}});
  ASSERT_TRUE(raw);
  EXPECT_EQ((*raw)["code"], "bad-argument") << raw->dump();
  EXPECT_FALSE(std::filesystem::exists(dir.file("state/snapshots/nocam.png")));
}

TEST(ProcamctlOperations, LatencyAndListArguments) {
  TempDir dir;
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "handheld"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  int status = -1;
  const json latency = ctlJson(d, {"latency", "repeats=2", "cameras=cam"}, status);
  ASSERT_EQ(status, 0) << latency.dump();
  EXPECT_EQ(latency["class"], "LATENCY");
  EXPECT_EQ(latency["state"], "done");
  EXPECT_EQ(latency["repeats"], 2);
  ASSERT_EQ(latency["cameras"].size(), 1u);
  // The handheld scene's camera sees the output one frame late at most.
  EXPECT_GE(latency.value("latency_s", -1.0), 0.0);
  EXPECT_LT(latency.value("latency_s", 1.0), 0.1 * kSlowdown);
  // One camera is route (b'): the daemon, not the client, says what is missing.
  const json one = ctlJson(d, {"calibrate", "cameras=cam", "plane=[0,1,0,-2]"}, status);
  EXPECT_EQ(status, 5) << one.dump();
  EXPECT_NE(one.value("message", "").find("'cam' is not calibrated"), std::string::npos)
      << one.dump();
  ctlJson(d, {"calibrate", "cameras=a,,b"}, status);
  EXPECT_EQ(status, 2);
  ctlJson(d, {"calibrate", "plane=[0,1"}, status);
  EXPECT_EQ(status, 2);
}

// A recording whose every pixel is known: a quarter at full scale, a quarter black,
// the rest mid-grey that tells the frames apart.
constexpr int kFrames = 40;
cv::Mat recordedFrame(int i) {
  cv::Mat img(48, 64, CV_8UC1, cv::Scalar(60 + i));
  img(cv::Rect(0, 0, 32, 24)).setTo(255);
  img(cv::Rect(32, 24, 32, 24)).setTo(0);
  return img;
}

TEST(Snapshot, ReplayedFrameIsWrittenExactly) {
  TempDir recording;
  std::ostringstream index;
  index << "file,timestamp\n";
  for (int i = 0; i < kFrames; ++i) {
    const std::string name = "f" + std::to_string(i) + ".png";
    ASSERT_TRUE(cv::imwrite(recording.file(name), recordedFrame(i)));
    index << name << "," << 100.0 + i * 0.25 << "\n";
  }
  recording.write("index.csv", index.str());
  TempDir dir;
  dir.write("procamd.toml",
            "[[camera]]\nname = \"rec\"\ndriver = \"replay\"\n[camera.options]\ndir = \"" +
                recording.path() + "\"\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml")}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto shot = c.call({{"cmd", "snapshot"}, {"camera", "rec"}}, 10s);
  ASSERT_TRUE(shot) << d.log();
  ASSERT_EQ((*shot)["class"], "SNAPSHOT") << shot->dump();
  EXPECT_EQ((*shot)["width"], 64);
  EXPECT_EQ((*shot)["height"], 48);
  EXPECT_TRUE((*shot)["exposure_s"].is_null());  // a recording has no settings
  EXPECT_TRUE((*shot)["gain"].is_null());
  EXPECT_NEAR(shot->value("saturated_pct", -1.0), 25.0, 1e-9);
  EXPECT_NEAR(shot->value("underexposed_pct", -1.0), 25.0, 1e-9);
  const cv::Mat img = cv::imread(shot->value("path", ""), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(img.type(), CV_8UC1);
  const int i = img.at<uint8_t>(40, 10) - 60;  // which frame it was
  ASSERT_TRUE(i >= 0 && i < kFrames) << i;
  EXPECT_EQ(cv::norm(img, recordedFrame(i), cv::NORM_INF), 0.0) << "frame " << i;
}

}  // namespace
}  // namespace procam::itest
