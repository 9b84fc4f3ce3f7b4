// The ir_camera tracker driver end to end through the plugin table, on replay recordings
// synthesized here: gray8 PNGs of Gaussian LED blobs rendered from a known head
// trajectory (LEDs 6 cm apart at 2 m, blob centres jittered by 0.1 px; f = 4000 px, the
// lens positionCovariance's bound asks for, see unit/tracking/led_trajectory.hpp).
// Head-tracking bounds: position <= 2 mm RMS, filtered latency within one frame of the raw
// signal.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "loader.hpp"
#include "registry.hpp"
#include "tracker/plugin/tracker_plugin.hpp"
#include "unit/tracking/led_trajectory.hpp"

namespace procam::tracker {
namespace {

namespace fs = std::filesystem;
using tracking::synthetic::capCamera;
using tracking::synthetic::headAt;
using tracking::synthetic::kCapLeds;
using Kv = std::vector<std::pair<std::string, std::string>>;

constexpr double kRate = 60;  // Hz
constexpr double kFrame = 1 / kRate;

// A replay folder of `frames` 1280x1024 gray8 PNGs at 60 Hz: Gaussian spots (sigma
// 1.5 px, 200 DN) at the LEDs' projections plus N(0, 0.1 px), or empty frames.
class Recording {
 public:
  Recording(int frames, bool leds, uint64_t seed = 1) {
    dir_ = fs::temp_directory_path() /
           ("procam-ir-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    fs::create_directories(dir_);
    std::ofstream index(dir_ / "index.csv");
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0, 0.1);
    const geom::CameraModel cam = capCamera();
    for (int k = 0; k < frames; ++k) {
      Points2 centres;
      for (size_t i = 0; leds && i < kCapLeds.size(); ++i)
        centres.push_back(*cam.project(headAt(k * kFrame).led(i)) + Vec2(n(rng), n(rng)));
      const cv::Mat img = tracking::synthetic::renderSpots(cam.width, cam.height, centres);
      const std::string name = "f" + std::to_string(k) + ".png";
      cv::imwrite((dir_ / name).string(), img, {cv::IMWRITE_PNG_COMPRESSION, 1});
      char stamp[32];
      std::snprintf(stamp, sizeof stamp, "%.9f", k * kFrame);
      index << name << "," << stamp << "\n";
    }
  }
  ~Recording() { fs::remove_all(dir_); }
  std::string dir() const { return dir_.string(); }

 private:
  static inline int counter_ = 0;
  fs::path dir_;
};

std::string ledsOption() {
  std::string s;
  for (const Vec3& p : kCapLeds) {
    char item[96];
    std::snprintf(item, sizeof item, "%s%.6f,%.6f,%.6f", s.empty() ? "" : ";", p.x(), p.y(), p.z());
    s += item;
  }
  return s;
}

// The options of a tracker on `dir` with capCamera()'s intrinsics and pose.
Kv trackerOptions(const std::string& dir) {
  return {{"camera_driver", "replay"},
          {"camera.dir", dir},
          {"camera.speed", "0"},
          {"fx", "4000"},
          {"fy", "4000"},
          {"cx", "639.5"},
          {"cy", "511.5"},
          {"camera_position", "0,0,0"},
          {"camera_look_at", "0,0,2"},
          {"camera_up", "0,1,0"},
          {"leds", ledsOption()}};
}

plugins::Driver irCamera() {
  const plugins::StaticPlugin table[] = {{"tracker", &procam_tracker_plugin_entry}};
  auto drivers = plugins::loadStaticPlugins(table);
  EXPECT_TRUE(drivers) << drivers.error().message;
  for (const auto& d : *drivers)
    if (d.name() == "ir_camera") return d;
  ADD_FAILURE() << "no ir_camera driver";
  return {};
}

plugins::DeviceDescription configured() {
  plugins::DeviceDescription d;
  d.family = PROCAM_FAMILY_TRACKER;
  d.subsystem = "config";
  d.name = "head";
  d.properties = {{"PROCAM_ROLE", "tracker"}};
  return d;
}

struct Read {
  int status = PROCAM_EINTERNAL;
  std::string reason;
  procam_pose_sample sample{};
};
Read readOnce(const plugins::Device& d) {
  Read r;
  char err[256] = {};
  r.status = d.raw().ops.tracker->read(d.raw().self, &r.sample, err, sizeof err);
  r.reason = err;
  return r;
}

Result<plugins::Device> open(const plugins::Driver& driver, const Kv& options) {
  auto desc = configured();
  return plugins::createDevice(driver, desc, options);
}

TEST(IrCameraTracker, ReplayMeetsTwoMillimetresAndOneFrameOfLag) {
  const int frames = 150;
  const Recording rec(frames, true);
  auto dev = open(irCamera(), trackerOptions(rec.dir()));
  ASSERT_TRUE(dev) << dev.error().message;
  EXPECT_GE(dev->pollFd(), 0);  // the replay camera's timerfd
  std::vector<double> times, raw_x, out_x;
  double raw_sq = 0, angle_sq = 0;
  uint64_t first_ns = 0;
  int k = 0;
  for (; k < frames; ++k) {
    const Read r = readOnce(*dev);
    ASSERT_EQ(r.status, PROCAM_OK) << "frame " << k << ": " << r.reason;
    const tracking::TrackedPose* pose = tracker::plugin::irCameraLastPose(dev->raw());
    ASSERT_NE(pose, nullptr);
    if (k == 0) first_ns = r.sample.timestamp_ns;
    // Frame times are the recording's (replay start + recorded offset).
    const double t = static_cast<double>(r.sample.timestamp_ns - first_ns) * 1e-9;
    EXPECT_NEAR(t, k * kFrame, 1e-6);
    const tracking::synthetic::HeadPose truth = headAt(k * kFrame);
    raw_sq += (pose->raw - truth.t).squaredNorm();
    const Eigen::Quaterniond q(r.sample.orientation[0], r.sample.orientation[1],
                               r.sample.orientation[2], r.sample.orientation[3]);
    EXPECT_NEAR(q.norm(), 1.0, 1e-9);
    const double angle = q.angularDistance(Eigen::Quaterniond(truth.R));
    angle_sq += angle * angle;
    if (k < 30) continue;  // filter settling
    times.push_back(k * kFrame);
    raw_x.push_back(pose->raw.x());
    out_x.push_back(r.sample.position[0]);
  }
  const Read end = readOnce(*dev);
  EXPECT_EQ(end.status, PROCAM_EEND) << end.reason;
  EXPECT_NE(end.reason.find("end of the recording"), std::string::npos) << end.reason;

  auto truth_x = [](double t) { return headAt(t).t.x(); };
  const double raw_rms = std::sqrt(raw_sq / frames), angle_rms = std::sqrt(angle_sq / frames);
  const double raw_lag = tracking::synthetic::lagBehind(times, raw_x, truth_x);
  const double lag = tracking::synthetic::lagBehind(times, out_x, truth_x);
  std::printf("raw RMS %.2f mm, orientation RMS %.3f deg, lag raw %.1f ms, output %.1f ms\n",
              raw_rms * 1e3, angle_rms * 180 / M_PI, raw_lag * 1e3, lag * 1e3);
  EXPECT_LE(raw_rms, 2e-3);
  EXPECT_LE(std::abs(lag - raw_lag), kFrame);
  // Out-of-plane turns: sigma ~ sigma_px z / (f dz) ~ 0.1 deg (test_led_tracker.cpp).
  EXPECT_LT(angle_rms, 0.25 * M_PI / 180);
}

TEST(IrCameraTracker, RegistrationAndPredictionShapeTheOutput) {
  const Recording rec(40, true, 2);
  Kv o = trackerOptions(rec.dir());
  o.push_back({"to_world_rvec", "0,0,1.5707963267948966"});  // 90 deg about z
  o.push_back({"to_world_t", "1,2,3"});
  o.push_back({"prediction_s", "0.05"});
  auto dev = open(irCamera(), o);
  ASSERT_TRUE(dev) << dev.error().message;
  for (int k = 0; k < 40; ++k) {
    const Read r = readOnce(*dev);
    ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
    const tracking::TrackedPose* pose = tracker::plugin::irCameraLastPose(dev->raw());
    const Vec3 t = headAt(k * kFrame).t;
    // x_world = R_z(90) x + (1, 2, 3) = (1 - y, 2 + x, 3 + z); 6 mm: ~3 sigma of a frame.
    EXPECT_LT((pose->raw - Vec3(1 - t.y(), 2 + t.x(), 3 + t.z())).norm(), 6e-3) << k;
    const Vec3 out(r.sample.position[0], r.sample.position[1], r.sample.position[2]);
    EXPECT_LT((out - (pose->filtered + 0.05 * pose->velocity)).norm(), 1e-12);
  }
}

TEST(IrCameraTracker, UnseenLedsAreAgainWithAReason) {
  const Recording rec(3, false);
  auto dev = open(irCamera(), trackerOptions(rec.dir()));
  ASSERT_TRUE(dev) << dev.error().message;
  const Read r = readOnce(*dev);
  EXPECT_EQ(r.status, PROCAM_EAGAIN);
  EXPECT_NE(r.reason.find("LEDs not seen: 0 blob(s)"), std::string::npos) << r.reason;
}

TEST(IrCameraTracker, BadOptionsGiveClearErrors) {
  const Recording rec(2, true);
  const plugins::Driver driver = irCamera();
  struct Case {
    const char* key;
    const char* value;  // nullptr: remove the key
    int status;
    const char* says;
  };
  const Case cases[] = {
      {"leds", nullptr, PROCAM_EINVAL, "option leds"},
      {"leds", "0,0,0;1,0,0;0,1,0", PROCAM_EINVAL, "at least 4 LEDs"},
      {"leds", "0,0,0;1,0;0,1,0;1,1,1", PROCAM_EINVAL, "x,y,z;x,y,z"},
      {"fx", nullptr, PROCAM_EINVAL, "option fx"},
      {"fy", "-3", PROCAM_EINVAL, "fy: must be > 0"},
      {"camera_driver", "nosuch", PROCAM_EINVAL, "unknown camera_driver 'nosuch' (replay, v4l2"},
      {"camera_driver", nullptr, PROCAM_EINVAL, "camera_driver is needed"},
      {"filter", "median", PROCAM_EINVAL, "'median' is not one_euro or kalman"},
      {"prediction_s", "-0.1", PROCAM_EINVAL, "prediction_s: must be >= 0"},
      {"exposure", "0.01", PROCAM_EINVAL, "unknown option 'exposure'"},
      {"camera.speed", "-1", PROCAM_EINVAL, "replay camera: speed must be >= 0"},
      {"camera.dir", "/nonexistent/recording", PROCAM_ENODEV, "camera driver 'replay'"},
      {"camera.pixel", "rgb8", PROCAM_EINVAL, "delivers rgb8"},
      {"threshold", "-5", PROCAM_EINVAL, "ir_camera tracker"},
      {"camera_rvec", "0,0,0", PROCAM_EINVAL, "not both"},
  };
  for (const Case& c : cases) {
    Kv o = trackerOptions(rec.dir());
    std::erase_if(o, [&](const auto& kv) { return kv.first == c.key; });
    if (c.value) o.push_back({c.key, c.value});
    auto desc = configured();
    procam_device raw{};
    char err[512] = {};
    std::vector<procam_kv> kv;
    for (const auto& [k, v] : o) kv.push_back({k.c_str(), v.c_str()});
    const procam_config config{kv.data(), kv.size()};
    const int status = driver.factory->create(&desc.view(), &config, &raw, err, sizeof err);
    EXPECT_EQ(status, c.status) << c.key << ": " << err;
    EXPECT_NE(std::string(err).find(c.says), std::string::npos) << c.key << ": " << err;
    if (status == PROCAM_OK) raw.destroy(raw.self);
  }
}

TEST(IrCameraTracker, ProbeTakesVideoNodesTaggedAsTrackers) {
  const plugins::Driver driver = irCamera();
  auto score = [&](const char* subsystem, const char* devnode, const char* role) {
    plugins::DeviceDescription d;
    d.family = PROCAM_FAMILY_TRACKER;
    d.subsystem = subsystem;
    d.devnode = devnode;
    if (role) d.properties = {{"PROCAM_ROLE", role}};
    return driver.factory->probe(&d.view());
  };
  EXPECT_EQ(score("video4linux", "/dev/video2", "tracker"), 50);
  EXPECT_EQ(score("video4linux", "/dev/video2", "camera"), 0);  // a camera, not a tracker
  EXPECT_EQ(score("hidraw", "/dev/hidraw0", "tracker"), 0);     // the Wii Remote's hid driver
  EXPECT_EQ(score("config", "", "tracker"), 0);                 // used when named
}

TEST(IrCameraTracker, LoadableObjectThroughTheLoader) {
  auto drivers = plugins::loadSharedPlugin(PROCAM_TRACKER_PLUGIN_PATH);
  ASSERT_TRUE(drivers) << drivers.error().message;
  const plugins::Driver* ir = nullptr;
  for (const auto& d : *drivers)
    if (d.name() == "ir_camera") ir = &d;
  ASSERT_NE(ir, nullptr);
  EXPECT_EQ(ir->origin, PROCAM_TRACKER_PLUGIN_PATH);
  const Recording rec(2, true);
  auto dev = open(*ir, trackerOptions(rec.dir()));
  ASSERT_TRUE(dev) << dev.error().message;
  const Read r = readOnce(*dev);
  ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
  EXPECT_LT(
      (Vec3(r.sample.position[0], r.sample.position[1], r.sample.position[2]) - headAt(0).t).norm(),
      6e-3);
}

}  // namespace
}  // namespace procam::tracker
