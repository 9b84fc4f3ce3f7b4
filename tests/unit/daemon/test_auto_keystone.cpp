// Auto keystone's daemon side and the output frames, without the daemon: the
// [keystone] configuration, rig.json intrinsics and frame rendering. The pure parts
// (tilt tracker, solve from gravity) are tested in tests/unit/keystone.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "auto_keystone.hpp"
#include "config.hpp"
#include "core/units.hpp"
#include "output_frames.hpp"
#include "rig_store.hpp"

namespace procam::daemon {
namespace {

// The handheld scene's MPU-6050 mount: chip x right, y forward, z up.
Mat3 handheldMount() {
  Mat3 M;
  M << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return M;
}

TEST(KeystoneConfigKeys, ParsedCheckedAndTheMountMustBeARotation) {
  auto ok = parseConfig(
      "[keystone]\ncutoff_hz = 5.0\nhysteresis_deg = 0.05\npoll_hz = 200\n"
      "mount = [1, 0, 0, 0, 0, 1, 0, -1, 0]\naccel_offset_g = [0.01, 0.0, -0.02]\n",
      "k.toml");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->keystone.cutoff_hz, 5.0);
  EXPECT_EQ(ok->keystone.hysteresis_deg, 0.05);
  EXPECT_EQ(ok->keystone.poll_hz, 200.0);
  auto mount = mountFromConfig(ok->keystone);
  ASSERT_TRUE(mount);
  EXPECT_EQ(mount->sensor_from_projector, handheldMount());
  EXPECT_EQ(mount->calibration.offset, Vec3(0.01, 0.0, -0.02));
  const keystone::TiltFilterOptions filter = tiltFilterOptions(ok->keystone);
  EXPECT_EQ(filter.cutoff_hz, 5.0);
  EXPECT_NEAR(filter.hysteresis, degToRad(0.05), 1e-18);

  auto bad =
      parseConfig("[keystone]\n\nhysteresis_deg = -1\nmount = [1, 2]\nspeed = 3\n", "k.toml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("k.toml:3: keystone.hysteresis_deg"), std::string::npos)
      << bad.error().message;
  EXPECT_NE(bad.error().message.find("keystone.mount: expected an array of 9 numbers"),
            std::string::npos);
  EXPECT_NE(bad.error().message.find("keystone.speed: unknown key"), std::string::npos);

  // The camera's yaw: on with 64 frames unless told; bounded.
  EXPECT_TRUE(ok->keystone.camera_yaw);
  EXPECT_EQ(ok->keystone.yaw_frames, 64);
  auto yaw = parseConfig("[keystone]\ncamera_yaw = false\nyaw_frames = 12\n", "k.toml");
  ASSERT_TRUE(yaw) << yaw.error().message;
  EXPECT_FALSE(yaw->keystone.camera_yaw);
  EXPECT_EQ(yaw->keystone.yaw_frames, 12);
  auto bad_yaw = parseConfig("[keystone]\ncamera_yaw = 1\nyaw_frames = 0\n", "k.toml");
  ASSERT_FALSE(bad_yaw);
  EXPECT_NE(bad_yaw.error().message.find("keystone.camera_yaw"), std::string::npos);
  EXPECT_NE(bad_yaw.error().message.find("keystone.yaw_frames"), std::string::npos);

  KeystoneConfig skew;
  skew.mount = std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0.5, 1};
  EXPECT_FALSE(mountFromConfig(skew));
}

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    char tmpl[] = "/tmp/procam-ak.XXXXXX";
    path = ::mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
};

TEST(RigStore, ReadsAVersion1RigAndItsProjectorsIntrinsics) {
  TempDir dir;
  auto none = loadRig(dir.path);
  ASSERT_TRUE(none) << none.error().message;
  EXPECT_TRUE(none->rig.empty());
  std::ofstream(dir.path / "rig.json")
      << R"({"cameras": [], "projectors": [{"name": "proj", "width": 1920, "height": 1080,
            "K": [2000, 0, 959.5, 0, 2010, 539.5, 0, 0, 1], "R": [1,0,0,0,1,0,0,0,1],
            "t": [0, 0, 0]}]})";
  auto loaded = loadRig(dir.path);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const rig::RigProjector* p = loaded->rig.projectorForOutput("proj");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->K.fx, 2000);
  EXPECT_EQ(p->K.fy, 2010);
  EXPECT_EQ(p->K.cx, 959.5);
  EXPECT_EQ(p->width, 1920);
  EXPECT_EQ(p->output, "");                                // version 1: not bound to an output
  EXPECT_EQ(loaded->rig.projectorForOutput("beamer"), p);  // the only one serves any output
  std::filesystem::remove(dir.path / "rig.json.bak");
  std::ofstream(dir.path / "rig.json") << R"({"projectors": [{"name": "proj", "K": [1, 2]}]})";
  std::filesystem::remove(dir.path / "rig.json.bak");
  auto bad = loadRig(dir.path);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kParse);
}

TEST(OutputFrames, PatternsContentAndTheWarp) {
  FrameRequest r;
  r.output_size = cv::Size(64, 32);
  r.pattern = "white";
  r.pattern_image = patternImage(r.pattern, r.output_size);
  auto white = renderOutputFrame(r);
  ASSERT_TRUE(white) << white.error().message;
  EXPECT_EQ(white->stats.source, "pattern:white");
  EXPECT_DOUBLE_EQ(white->stats.lit_fraction, 1.0);
  EXPECT_EQ(white->rgba.size(), r.output_size);

  // Half size towards the origin, pixel edges to pixel edges: the top-left
  // quarter (32 x 16 pixel centres) is lit.
  Mat3 H;
  H << 0.5, 0, -0.25, 0, 0.5, -0.25, 0, 0, 1;
  r.homography = H;
  auto quarter = renderOutputFrame(r);
  ASSERT_TRUE(quarter);
  EXPECT_DOUBLE_EQ(quarter->stats.lit_fraction, 0.25);

  // A red 4x4 image in a 64x32 frame without a warp: fitted to 32x32, centred.
  auto red = std::make_shared<cv::Mat>(4, 4, CV_8UC4, cv::Scalar(255, 0, 0, 255));
  r.pattern = "off";
  r.content = red;
  r.homography.reset();
  EXPECT_EQ(sourceSize(r), cv::Size(4, 4));
  auto fitted = renderOutputFrame(r);
  ASSERT_TRUE(fitted);
  EXPECT_EQ(fitted->stats.source, "content");
  EXPECT_DOUBLE_EQ(fitted->stats.lit_fraction, 0.5);
  EXPECT_DOUBLE_EQ(fitted->stats.mean_rgb[0], 127.5);
  EXPECT_DOUBLE_EQ(fitted->stats.mean_rgb[1], 0.0);
  EXPECT_EQ(fitted->rgba.at<cv::Vec4b>(16, 32), cv::Vec4b(255, 0, 0, 255));  // R G B A
  EXPECT_EQ(fitted->rgba.at<cv::Vec4b>(16, 8), cv::Vec4b(0, 0, 0, 0));

  r.content.reset();
  auto none = renderOutputFrame(r);
  ASSERT_TRUE(none);
  EXPECT_EQ(none->stats.source, "none");
  EXPECT_EQ(cv::countNonZero(none->rgba.reshape(1)), 0);
}

TEST(OutputFrames, DecodedContentIsRgba) {
  TempDir dir;
  const std::string png = (dir.path / "grey.png").string();
  cv::imwrite(png, cv::Mat(3, 5, CV_8UC1, cv::Scalar(77)));
  ContentAccess access;
  access.roots = {dir.path.string()};
  auto img = decodeContent(access, png);
  ASSERT_TRUE(img) << img.error().message;
  EXPECT_EQ(img->image->type(), CV_8UC4);
  EXPECT_EQ(img->image->size(), cv::Size(5, 3));
  EXPECT_EQ(img->image->at<cv::Vec4b>(1, 1), cv::Vec4b(77, 77, 77, 255));
  EXPECT_EQ(decodeContent(access, "grey.png")->path, std::filesystem::canonical(png).string());
  EXPECT_EQ(decodeContent(access, (dir.path / "none.png").string()).error().code, ErrorCode::kIo);
  access.limits.image_pixels = 14;  // the header says 15 pixels
  EXPECT_EQ(decodeContent(access, png).error().code, ErrorCode::kTooLarge);
  access.roots = {(dir.path / "sub").string()};
  std::filesystem::create_directory(dir.path / "sub");
  EXPECT_EQ(decodeContent(access, png).error().code, ErrorCode::kForbidden);
  EXPECT_EQ(decodeContent(access, "../grey.png").error().code, ErrorCode::kForbidden);
}

}  // namespace
}  // namespace procam::daemon
