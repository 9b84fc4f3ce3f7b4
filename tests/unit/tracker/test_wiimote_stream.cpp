// The hid tracker driver end to end on the stored Wii Remote report stream
// (data/wiimote_ir_stream.csv, written by wiimote_stream_gen from wiimote_stream.hpp):
// the setup handshake with a fake Wii Remote, then every report through the plugin's
// read(). The reports' 10-bit grid is the only error: uniform quantisation,
// sigma = 1/sqrt(12) px per coordinate, so the raw position's error is bounded by
// positionCovariance at that sigma (first order).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>

#include "loader.hpp"
#include "tracker/plugin/hid_plugin.hpp"
#include "tracker/plugin/tracker_plugin.hpp"
#include "tracking/constellation_pose.hpp"
#include "unit/tracker/fake_wiimote.hpp"
#include "unit/tracker/wiimote_stream.hpp"

namespace procam::tracker::wiimote {
namespace {

using testing::FakeWiimote;
using Kv = std::vector<std::pair<std::string, std::string>>;

const double kQuantSigma = 1 / std::sqrt(12.0);

std::string storedPath() {
  return std::string(PROCAM_WIIMOTE_STREAM);
}

std::string ledsOption() {
  std::ostringstream s;
  for (std::size_t i = 0; i < testing::kLeds.size(); ++i)
    s << (i ? ";" : "") << testing::kLeds[i].x() << "," << testing::kLeds[i].y() << ","
      << testing::kLeds[i].z();
  return s.str();
}

struct Device {
  procam_device dev{};
  int rc = 0;
  std::string err = std::string(512, '\0');
  FakeWiimote* fake = nullptr;  // owned by the device once created
  std::shared_ptr<std::vector<Report>> written;
  ~Device() {
    if (rc == PROCAM_OK && dev.destroy) dev.destroy(dev.self);
  }
};

void create(Device& d, std::unique_ptr<FakeWiimote> fake, const Kv& options) {
  std::vector<procam_kv> kv;
  for (const auto& [k, v] : options) kv.push_back({k.c_str(), v.c_str()});
  const procam_config config{kv.data(), kv.size()};
  d.fake = fake.get();
  d.written = fake->written;
  FakeWiimote* raw = d.fake;
  d.rc = plugin::createWiimoteOn(
      std::move(fake), &config, [raw] { return raw->now_ns; }, &d.dev, d.err.data(),
      d.err.size() - 1);
}

TEST(WiimoteStream, StoredStreamIsTheGeneratorsOutput) {
  auto stored = testing::read(storedPath());
  ASSERT_TRUE(stored) << "cannot read " << storedPath();
  const auto fresh = testing::generate();
  ASSERT_EQ(stored->size(), fresh.size());
  for (std::size_t k = 0; k < fresh.size(); ++k) {
    EXPECT_EQ((*stored)[k].report, fresh[k].report) << "report " << k;
    EXPECT_NEAR((*stored)[k].time, fresh[k].time, 1e-9);
    EXPECT_LT(((*stored)[k].truth - fresh[k].truth).norm(), 1e-8);
  }
}

TEST(WiimoteStream, PoseMatchesTruthWithinTheQuantisationBound) {
  auto stream = testing::read(storedPath());
  ASSERT_TRUE(stream);
  auto fake = std::make_unique<FakeWiimote>();
  for (const auto& r : *stream)
    fake->inbox.push_back({r.report, std::uint64_t(std::llround(r.time * 1e9))});
  Device d;
  create(d, std::move(fake), {{"leds", ledsOption()}, {"filter", "kalman"}});
  ASSERT_EQ(d.rc, PROCAM_OK) << d.err.c_str();

  const geom::CameraModel cam = wiimoteCamera();
  double sum_sq = 0, sum_sq_normalised = 0, worst_sigmas = 0;
  int poses = 0, unseen = 0;
  for (std::size_t k = 0; k < stream->size(); ++k) {
    procam_pose_sample s{};
    char err[256] = {};
    const int rc = d.dev.ops.tracker->read(d.dev.self, &s, err, sizeof err - 1);
    const bool hidden = int(k) >= testing::kHiddenFrom && int(k) < testing::kHiddenTo;
    if (hidden) {
      EXPECT_EQ(rc, PROCAM_EAGAIN) << "report " << k;
      EXPECT_NE(std::strstr(err, "LEDs not seen: 3 blob(s)"), nullptr) << err;
      ++unseen;
      continue;
    }
    ASSERT_EQ(rc, PROCAM_OK) << "report " << k << ": " << err;
    EXPECT_EQ(s.timestamp_ns, std::uint64_t(std::llround((*stream)[k].time * 1e9)));
    const tracking::TrackedPose* pose = plugin::wiimoteLastPose(d.dev);
    ASSERT_NE(pose, nullptr);
    EXPECT_EQ(pose->matched, 4);
    EXPECT_LE(pose->rms_px, 0.5 * std::sqrt(2.0));  // rounding moves a blob <= 0.71 px
    for (int i = 0; i < 3; ++i) EXPECT_EQ(s.position[i], pose->predicted(i));

    // The bound at the true pose, cap -> camera.
    const testing::CapPose truth = testing::capAt((*stream)[k].time);
    geom::Pose cap_to_cam;
    cap_to_cam.R = truth.R;
    cap_to_cam.t = truth.t;
    const Mat3 cov = tracking::positionCovariance(cam.K, cap_to_cam, testing::kLeds, kQuantSigma);
    const Vec3 e = pose->raw - (*stream)[k].truth;
    for (int i = 0; i < 3; ++i) {
      const double sigma = std::sqrt(cov(i, i));
      worst_sigmas = std::max(worst_sigmas, std::abs(e(i)) / sigma);
      sum_sq_normalised += e(i) * e(i) / cov(i, i);
    }
    sum_sq += e.squaredNorm();
    ++poses;
  }
  ASSERT_EQ(unseen, testing::kHiddenTo - testing::kHiddenFrom);
  ASSERT_EQ(poses, testing::kReports - unseen);
  const double rms_mm = 1e3 * std::sqrt(sum_sq / poses);
  const double rms_sigmas = std::sqrt(sum_sq_normalised / (3.0 * poses));
  std::printf("wiimote stream: %d poses, position RMS %.2f mm, %.2f sigma RMS, worst %.2f sigma\n",
              poses, rms_mm, rms_sigmas, worst_sigmas);
  // Uniform quantisation is bounded: no axis beyond 4 sigma, and the errors are as large
  // as the first-order bound says on average (RMS of the normalised errors about 1).
  EXPECT_LT(worst_sigmas, 4.0);
  EXPECT_LT(rms_sigmas, 1.5);
}

TEST(WiimoteStream, SetupFailureIsReportedByCreate) {
  auto fake = std::make_unique<FakeWiimote>();
  fake->error_ack = {{0x13, 0x04}};
  Device d;
  create(d, std::move(fake), {{"leds", ledsOption()}});
  EXPECT_EQ(d.rc, PROCAM_EIO);
  EXPECT_STREQ(d.err.c_str(),
               "wiimote: IR setup step 'IR pixel clock on', IR pixel clock (0x13): the Wii "
               "Remote answered error 0x04");
}

TEST(WiimoteStream, OptionsAreCheckedAndTheCameraIsOverridable) {
  for (const auto& [options, why] : std::vector<std::pair<Kv, std::string>>{
           {{}, "the LED layout is needed"},
           {{{"leds", ledsOption()}, {"ir_format", "full"}}, "'full' is not extended or basic"},
           {{{"leds", ledsOption()}, {"sensitivity", "0"}}, "sensitivity must be 1..5"},
           {{{"leds", ledsOption()}, {"fx", "-3"}}, "fx: must be > 0"},
           {{{"leds", ledsOption()}, {"colour", "red"}}, "colour"}}) {
    Device d;
    create(d, std::make_unique<FakeWiimote>(), options);
    EXPECT_EQ(d.rc, PROCAM_EINVAL) << why;
    EXPECT_NE(std::string(d.err.c_str()).find(why), std::string::npos) << d.err.c_str();
    EXPECT_TRUE(d.written->empty());  // nothing reaches the device
  }
  // A calibrated camera replaces the default: the first report's pose moves with f.
  auto stream = testing::read(storedPath());
  ASSERT_TRUE(stream);
  auto fake = std::make_unique<FakeWiimote>();
  fake->inbox.push_back({stream->front().report, 1});
  Device d;
  create(d, std::move(fake), {{"leds", ledsOption()}, {"fx", "3456.966"}, {"fy", "3456.966"}});
  ASSERT_EQ(d.rc, PROCAM_OK) << d.err.c_str();
  procam_pose_sample s{};
  char err[256] = {};
  ASSERT_EQ(d.dev.ops.tracker->read(d.dev.self, &s, err, sizeof err - 1), PROCAM_OK) << err;
  // Twice the focal length: the same image says twice the distance.
  EXPECT_NEAR(plugin::wiimoteLastPose(d.dev)->raw.z(), 2 * stream->front().truth.z(), 0.02);
}

const procam_driver_factory& hidFactory() {
  const procam_plugin_table* table = procam_tracker_plugin_entry();
  for (std::size_t i = 0; i < table->n_factories; ++i)
    if (std::strcmp(table->factories[i].name, "hid") == 0) return table->factories[i];
  ADD_FAILURE() << "no hid driver in the tracker table";
  return table->factories[0];
}

int probe(const char* subsystem, const char* devnode, Kv properties,
          procam_family family = PROCAM_FAMILY_TRACKER, const char* syspath = nullptr) {
  std::vector<procam_kv> kv;
  for (const auto& [k, v] : properties) kv.push_back({k.c_str(), v.c_str()});
  procam_device_desc d{};
  d.family = family;
  d.subsystem = subsystem;
  d.devnode = devnode;
  d.syspath = syspath;
  d.properties = kv.data();
  d.n_properties = kv.size();
  return hidFactory().probe(&d);
}

TEST(WiimoteStream, ProbeTakesWiiRemotesAndConfiguredHidrawTrackers) {
  const Kv tracker = {{"PROCAM_ROLE", "tracker"}};
  auto with = [&](const char* hid_id) {
    Kv p = tracker;
    p.emplace_back("HID_ID", hid_id);
    return p;
  };
  EXPECT_EQ(probe("hidraw", "/dev/hidraw0", with("0005:0000057E:00000306")), 60);
  EXPECT_EQ(probe("hidraw", "/dev/hidraw0", with("0005:0000057E:00000330")), 60);
  EXPECT_EQ(probe("hidraw", "/dev/hidraw0", with("0003:0000131D:00000159")), 0);  // TrackIR
  EXPECT_EQ(probe("hidraw", "/dev/hidraw0", with("0005:0000057E:00000337")), 0);
  // Without HID_ID the hid device's name in the syspath decides.
  const char* wii_path = "/sys/devices/virtual/misc/uhid/0005:057E:0330.0007/hidraw/hidraw2";
  const char* trackir_path =
      "/sys/devices/pci0000:00/0000:00:14.0/usb1/1-2/1-2:1.0/"
      "0003:131D:0159.0003/hidraw/hidraw1";
  EXPECT_EQ(probe("hidraw", "/dev/hidraw2", tracker, PROCAM_FAMILY_TRACKER, wii_path), 60);
  EXPECT_EQ(probe("hidraw", "/dev/hidraw1", tracker, PROCAM_FAMILY_TRACKER, trackir_path), 0);
  EXPECT_EQ(probe("hidraw", "/dev/hidraw1", tracker), 0);
  // A tracker configured on a hidraw node.
  EXPECT_EQ(probe("config", "/dev/hidraw3", tracker), 30);
  EXPECT_EQ(probe("config", "/dev/video3", tracker), 0);
  EXPECT_EQ(probe("video4linux", "/dev/video0", tracker), 0);
  EXPECT_EQ(probe("hidraw", "/dev/hidraw0", {{"PROCAM_ROLE", "tilt"}}, PROCAM_FAMILY_TILT), 0);
}

TEST(WiimoteStream, CreateOnAMissingNodeIsNoDevice) {
  const std::string leds = ledsOption();
  const procam_kv kv[] = {{"leds", leds.c_str()}, {"hidraw", "/dev/hidraw-none"}};
  const procam_config config{kv, 2};
  procam_device dev{};
  char err[256] = {};
  EXPECT_EQ(hidFactory().create(nullptr, &config, &dev, err, sizeof err - 1), PROCAM_ENODEV);
  EXPECT_NE(std::strstr(err, "/dev/hidraw-none"), nullptr) << err;
}

TEST(WiimoteStream, LoadableObjectHasTheHidDriver) {
  auto drivers = plugins::loadSharedPlugin(PROCAM_TRACKER_PLUGIN_PATH);
  ASSERT_TRUE(drivers) << drivers.error().message;
  const plugins::Driver* hid = nullptr;
  for (const auto& d : *drivers)
    if (d.name() == "hid") hid = &d;
  ASSERT_NE(hid, nullptr);
  EXPECT_EQ(hid->family(), PROCAM_FAMILY_TRACKER);
  const procam_kv props[] = {{"PROCAM_ROLE", "tracker"}, {"HID_ID", "0005:0000057E:00000306"}};
  procam_device_desc desc{};
  desc.family = PROCAM_FAMILY_TRACKER;
  desc.subsystem = "hidraw";
  desc.devnode = "/dev/hidraw-none";
  desc.properties = props;
  desc.n_properties = 2;
  EXPECT_EQ(hid->factory->probe(&desc), 60);
  const std::string leds = ledsOption();
  const procam_kv kv[] = {{"leds", leds.c_str()}};
  const procam_config config{kv, 1};
  procam_device dev{};
  char err[256] = {};
  EXPECT_EQ(hid->factory->create(&desc, &config, &dev, err, sizeof err - 1), PROCAM_ENODEV);
  EXPECT_NE(std::strstr(err, "/dev/hidraw-none"), nullptr) << err;
}

}  // namespace
}  // namespace procam::tracker::wiimote
