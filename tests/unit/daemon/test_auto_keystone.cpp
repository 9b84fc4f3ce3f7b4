// Auto keystone's pieces and the output frames, without the daemon: the tilt
// tracker (calibration, filter, hysteresis), the solve from gravity, the
// [keystone] configuration, rig.json intrinsics and frame rendering.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "auto_keystone.hpp"
#include "config.hpp"
#include "keystone/keystone_solver.hpp"
#include "output_frames.hpp"
#include "rig_store.hpp"

namespace procam::daemon {
namespace {

constexpr double kG = 9.80665;
constexpr double kDeg = std::numbers::pi / 180;

// The handheld scene's MPU-6050 mount: chip x right, y forward, z up.
Mat3 handheldMount() {
  Mat3 M;
  M << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return M;
}

// A still reading (m/s^2) for gravity `down` (projector frame) through the mount,
// with a sensor offset (g).
procam_tilt_sample reading(const Mat3& sensor_from_projector, const Vec3& down, const Vec3& offset,
                           double t) {
  const Vec3 f = sensor_from_projector * (-down) + offset;
  procam_tilt_sample s{};
  for (int i = 0; i < 3; ++i) s.specific_force[i] = f[i] * kG;
  s.timestamp_ns = static_cast<uint64_t>(t * 1e9);
  return s;
}

double angle(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(TiltTracker, CalibratedStillReadingsGiveTheTrueGravityAndFewUpdates) {
  TiltMount mount;
  mount.sensor_from_projector = handheldMount();
  const Vec3 offset(0.05, -0.05, 0.05);  // the scene's bias, in g
  mount.calibration.offset = offset;
  auto tracker = TiltTracker::create(KeystoneConfig{}, mount);
  ASSERT_TRUE(tracker) << tracker.error().message;
  const Vec3 down =
      keystone::rotationFromAngles({12 * kDeg, -7 * kDeg, 0}) * Vec3(0, 0, -1);  // world -Z
  int published = 0;
  std::optional<Vec3> last;
  for (int k = 0; k < 2000; ++k) {  // 20 s at 100 Hz
    if (auto d = tracker->add(reading(mount.sensor_from_projector, down, offset, 0.01 * k))) {
      ++published;
      last = *d;
    }
  }
  ASSERT_TRUE(last);
  EXPECT_LT(angle(*last, down), 1e-6);
  // The first sample, then refinements of the still hold after 2, 4, 8, 16 s.
  EXPECT_LE(published, 6);
  EXPECT_TRUE(tracker->still());
}

TEST(TiltTracker, RepeatedAndNonFiniteSamplesAreIgnored) {
  // Garbage is the driver's to drop (its sample gate); what reaches the tracker
  // anyway must not disturb it.
  auto tracker = TiltTracker::create(KeystoneConfig{}, TiltMount{});
  ASSERT_TRUE(tracker);
  const Vec3 down(0, 1, 0);
  ASSERT_TRUE(tracker->add(reading(Mat3::Identity(), down, Vec3::Zero(), 1.0)));
  // The same timestamp again (a timer faster than the sensor): ignored.
  EXPECT_FALSE(tracker->add(reading(Mat3::Identity(), Vec3(1, 0, 0), Vec3::Zero(), 1.0)));
  procam_tilt_sample nan = reading(Mat3::Identity(), down, Vec3::Zero(), 1.01);
  nan.specific_force[0] = NAN;
  EXPECT_FALSE(tracker->add(nan));
  // The next good sample, turned by 10 degrees, moves the estimate part of the way
  // (a 10 Hz low-pass over 10 ms) and it stays finite.
  const Vec3 turned(0, std::cos(10 * kDeg), -std::sin(10 * kDeg));
  auto next = tracker->add(reading(Mat3::Identity(), turned, Vec3::Zero(), 1.02));
  ASSERT_TRUE(next);
  EXPECT_TRUE(next->allFinite());
  EXPECT_GT(angle(*next, down), 1 * kDeg);
  EXPECT_LT(angle(*next, down), 9 * kDeg);
}

TEST(SixPositionCollector, SixHoldsRecoverOffsetAndGain) {
  keystone::AccelCalibration truth;
  truth.offset = Vec3(0.03, -0.02, 0.05);
  truth.scale = Vec3(1.02, 0.97, 1.01);
  SixPositionCollector holds;
  const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (int i = 0; i < 6; ++i) {
    const Vec3 up = (i % 2 ? -1.0 : 1.0) * Vec3::Unit(i / 2);
    // Held 3 degrees off vertical: still accepted.
    const Vec3 f = Eigen::AngleAxisd(3 * kDeg, Vec3::Unit((i / 2 + 1) % 3)) * up;
    auto pose = holds.add(truth.scale.cwiseProduct(f) + truth.offset);
    ASSERT_TRUE(pose) << pose.error().message;
    EXPECT_EQ(*pose, names[i]);
    if (i == 4) {
      EXPECT_EQ(holds.missing(), std::vector<std::string>({"-z"}));
      EXPECT_EQ(holds.solve().error().code, ErrorCode::kTooFewPoints);
    }
  }
  auto fit = holds.solve();
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_LT((fit->calibration.offset - truth.offset).norm(), 1e-6);
  EXPECT_LT((fit->calibration.scale - truth.scale).norm(), 1e-6);
  // 45 degrees from every axis: not a hold of the procedure.
  EXPECT_FALSE(holds.add(Vec3(1, 1, 0).normalized()));
}

TEST(TiltTracker, StillMeanIsTheRawReading) {
  TiltMount mount;
  mount.calibration.offset = Vec3(0.1, 0, 0);  // applied to the filter, not to the mean
  auto tracker = TiltTracker::create(KeystoneConfig{}, mount);
  ASSERT_TRUE(tracker);
  const Vec3 raw(0.1, 0.2, 0.98);
  for (int k = 0; k < 100; ++k) {
    procam_tilt_sample s{};
    for (int i = 0; i < 3; ++i) s.specific_force[i] = raw[i] * kG;
    s.timestamp_ns = static_cast<uint64_t>(k * 1e7);
    tracker->add(s);
  }
  auto mean = tracker->stillMean();
  ASSERT_TRUE(mean);
  EXPECT_LT((mean->first - raw).norm(), 1e-12);
  EXPECT_GT(mean->second, 50);
}

TEST(SolveFromDown, EqualsTheKeystoneSolveAtThatTilt) {
  ProjectorModel p;
  p.K = geom::Intrinsics{1400, 1400, 639.5, 359.5, 0};
  p.width = 1280;
  p.height = 720;
  const keystone::Angles a{-15 * kDeg, 9 * kDeg, 0};
  const Mat3 R = keystone::rotationFromAngles(a);
  const Vec3 down = R * Vec3(0, 0, -1);
  auto e = solveFromDown(p, down, 1920, 1080);
  ASSERT_TRUE(e) << e.error().message;
  keystone::KeystoneProblem problem{p.K, 1280, 720, R, 1920, 1080, {}};
  auto truth = keystone::solveKeystone(problem);
  ASSERT_TRUE(truth);
  EXPECT_LT((e->H - truth->H).cwiseAbs().maxCoeff(), 1e-9 * truth->H.cwiseAbs().maxCoeff());
  EXPECT_NEAR(e->angles.pitch, a.pitch, 1e-12);
  EXPECT_NEAR(e->angles.roll, a.roll, 1e-12);
  EXPECT_EQ(e->content_width, 1920);
  // Tilted so far that part of the frame misses the wall: an error, not NaN.
  const Vec3 up_steep = keystone::rotationFromAngles({89 * kDeg, 0, 0}) * Vec3(0, 0, -1);
  EXPECT_FALSE(solveFromDown(p, up_steep, 1280, 720));
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

  auto bad =
      parseConfig("[keystone]\n\nhysteresis_deg = -1\nmount = [1, 2]\nspeed = 3\n", "k.toml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("k.toml:3: keystone.hysteresis_deg"), std::string::npos)
      << bad.error().message;
  EXPECT_NE(bad.error().message.find("keystone.mount: expected an array of 9 numbers"),
            std::string::npos);
  EXPECT_NE(bad.error().message.find("keystone.speed: unknown key"), std::string::npos);

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
  auto white = renderOutputFrame(r);
  ASSERT_TRUE(white) << white.error().message;
  EXPECT_EQ(white->stats.source, "pattern:white");
  EXPECT_DOUBLE_EQ(white->stats.lit_fraction, 1.0);
  EXPECT_EQ(white->rgb.size(), r.output_size);

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
  EXPECT_EQ(fitted->rgb.at<cv::Vec3b>(16, 32), cv::Vec3b(255, 0, 0));  // R G B
  EXPECT_EQ(fitted->rgb.at<cv::Vec3b>(16, 8), cv::Vec3b(0, 0, 0));

  r.content.reset();
  auto none = renderOutputFrame(r);
  ASSERT_TRUE(none);
  EXPECT_EQ(none->stats.source, "none");
  EXPECT_EQ(cv::countNonZero(none->rgb.reshape(1)), 0);
}

TEST(OutputFrames, DecodedContentIsRgba) {
  TempDir dir;
  const std::string png = (dir.path / "grey.png").string();
  cv::imwrite(png, cv::Mat(3, 5, CV_8UC1, cv::Scalar(77)));
  auto img = decodeContent(png);
  ASSERT_TRUE(img) << img.error().message;
  EXPECT_EQ((*img)->type(), CV_8UC4);
  EXPECT_EQ((*img)->size(), cv::Size(5, 3));
  EXPECT_EQ((*img)->at<cv::Vec4b>(1, 1), cv::Vec4b(77, 77, 77, 255));
  EXPECT_EQ(decodeContent((dir.path / "none.png").string()).error().code, ErrorCode::kIo);
}

}  // namespace
}  // namespace procam::daemon
