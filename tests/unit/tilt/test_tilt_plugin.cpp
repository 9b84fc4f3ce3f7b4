// The tilt drivers behind the plugin ABI: probe scores, option errors, reads through
// the simulated transports (register maps, a fake IIO tree, stored HID reports,
// scripted GPIO lines), garbage samples counted, and procam-tilt.so through the loader.
#include <gtest/gtest.h>

#include <cstring>

#include "fake_gpio.hpp"
#include "fake_hid.hpp"
#include "fake_i2c.hpp"
#include "fake_iio.hpp"
#include "loader.hpp"
#include "registry.hpp"
#include "tilt/plugin/plugin_support.hpp"
#include "tilt/plugin/tilt_plugin.hpp"

#ifndef PROCAM_TILT_GPIOD
#define PROCAM_TILT_GPIOD 0  // built without libgpiod: no gpio driver
#endif

namespace procam::tilt {
namespace {

using namespace testing;
using plugins::DeviceDescription;

constexpr double kG = kStandardGravity;

std::vector<plugins::Driver> staticDrivers() {
  const plugins::StaticPlugin table[] = {{"tilt", &procam_tilt_plugin_entry}};
  auto drivers = plugins::loadStaticPlugins(table);
  EXPECT_TRUE(drivers) << drivers.error().message;
  return drivers ? *drivers : std::vector<plugins::Driver>{};
}

DeviceDescription described(const char* subsystem, const char* devnode, const char* role,
                            procam_family family = PROCAM_FAMILY_TILT) {
  DeviceDescription d;
  d.family = family;
  d.subsystem = subsystem;
  d.devnode = devnode;
  if (role) d.properties = {{"PROCAM_ROLE", role}};
  return d;
}

using Kv = std::vector<std::pair<std::string, std::string>>;

// procam_config over text options (kept alive by the caller's vector).
struct Options {
  std::vector<procam_kv> kv;
  procam_config config{};
  explicit Options(const Kv& text = {}) : text_(text) {
    for (const auto& [k, v] : text_) kv.push_back({k.c_str(), v.c_str()});
    config = {kv.data(), kv.size()};
  }
  Options(const Options&) = delete;  // kv points into text_
  Options& operator=(const Options&) = delete;

 private:
  Kv text_;
};

// The driver's counts through the ABI (procam_tilt_ops::get_counts).
procam_tilt_counts counts(const plugins::Device& d) {
  auto c = plugins::tiltCounts(d.raw());
  EXPECT_TRUE(c) << "the tilt drivers report their counts";
  return c.value_or(procam_tilt_counts{});
}

// One read through the ABI, and whether the driver counted it as rejected.
struct Read {
  int status = PROCAM_EINTERNAL;
  std::string reason;
  procam_tilt_sample sample{};
  uint64_t newly_rejected = 0;
  bool rejected() const { return status == PROCAM_EAGAIN && newly_rejected == 1; }
};
Read readOnce(const plugins::Device& d) {
  Read r;
  char err[256] = {};
  const uint64_t before = plugins::rejectedSamples(counts(d));
  r.status = d.raw().ops.tilt->read(d.raw().self, &r.sample, err, sizeof err);
  r.reason = err;
  r.newly_rejected = plugins::rejectedSamples(counts(d)) - before;
  return r;
}
Vec3 force(const Read& r) {
  return Vec3(r.sample.specific_force[0], r.sample.specific_force[1], r.sample.specific_force[2]);
}

plugins::Device own(int status, const procam_device& raw, const char* err) {
  EXPECT_EQ(status, PROCAM_OK) << err;
  return status == PROCAM_OK ? plugins::Device(raw, nullptr, "tilt") : plugins::Device();
}

TEST(TiltPlugin, ProbeScoresFromSubsystemRoleAndDevnode) {
  auto drivers = staticDrivers();
  plugins::DriverRegistry registry;
  std::vector<std::string> refused;
  registry.addAll(drivers, refused);
  ASSERT_TRUE(refused.empty());
  ASSERT_EQ(drivers.size(), PROCAM_TILT_GPIOD ? 4u : 3u);

  struct Case {
    DeviceDescription desc;
    const char* driver;  // nullptr: no tilt driver takes it
    int score;
  };
  std::vector<Case> cases = {
      {described("iio", "/dev/iio:device0", "tilt"), "iio", 60},
      {described("iio", "/dev/iio:device1", nullptr), nullptr, 0},  // a light sensor
      {described("config", "/dev/iio:device2", "tilt"), "iio", 60},
      {described("i2c-dev", "/dev/i2c-1", "i2c-adapter"), "i2c", 40},
      {described("config", "/dev/i2c-3", "tilt"), "i2c", 40},
      {described("hidraw", "/dev/hidraw0", "tilt"), "hid", 40},
      {described("hidraw", "/dev/hidraw1", "tracker"), nullptr, 0},  // a TrackIR
      {described("iio", "/dev/iio:device0", "tilt", PROCAM_FAMILY_CAMERA), nullptr, 0},
      {described("sim", "", "tilt"), nullptr, 0},
  };
  if (PROCAM_TILT_GPIOD)
    cases.push_back({described("gpio", "/dev/gpiochip0", "gpiochip"), "gpio", 20});
  for (auto& c : cases) {
    SCOPED_TRACE(c.desc.subsystem + " " + c.desc.devnode);
    auto match = registry.bestMatch(c.desc);
    if (!c.driver) {
      EXPECT_FALSE(match);
      continue;
    }
    ASSERT_TRUE(match);
    EXPECT_EQ(match->driver.name(), c.driver);
    EXPECT_EQ(match->score, c.score);
  }
}

TEST(TiltPlugin, BadOptionsGiveClearErrors) {
  auto drivers = staticDrivers();
  plugins::DriverRegistry registry;
  std::vector<std::string> refused;
  registry.addAll(drivers, refused);
  struct Case {
    const char* driver;
    DeviceDescription desc;
    std::vector<std::pair<std::string, std::string>> options;
    const char* message;
  };
  std::vector<Case> cases = {
      {"i2c", described("config", "/dev/i2c-1", "tilt"), {}, "option chip is required"},
      {"i2c",
       described("config", "/dev/i2c-1", "tilt"),
       {{"chip", "bmi160"}},
       "'bmi160' is not adxl345, mpu6050 or lis3dh"},
      {"i2c",
       described("config", "/dev/i2c-1", "tilt"),
       {{"chip", "lis3dh"}, {"address", "0x99"}},
       "7-bit address"},
      {"i2c",
       described("config", "/dev/i2c-1", "tilt"),
       {{"chip", "lis3dh"}, {"address", "x18"}},
       "option address: 'x18' is not an integer"},
      {"iio",
       described("config", "/dev/iio:device0", "tilt"),
       {{"rate", "100"}},
       "unknown option 'rate' (known: device_dir, sysfs_root"},
      {"iio",
       described("config", "/dev/iio:device0", "tilt"),
       {{"sampling_hz", "fast"}},
       "option sampling_hz: 'fast' is not a number"},
      {"iio", described("config", "", "tilt"), {}, "no device"},
      {"iio",
       described("config", "/dev/iio:device0", "tilt"),
       {{"buffered", "maybe"}},
       "'maybe' is not true or false"},
      {"iio",
       described("config", "/dev/iio:device0", "tilt"),
       {{"max_norm_g", "0.2"}},
       "min_norm_g < max_norm_g"},
      {"hid", described("config", "", "tilt"), {}, "give hidraw = /dev/hidrawN"},
  };
  if (PROCAM_TILT_GPIOD) {
    cases.push_back({"gpio",
                     described("config", "/dev/gpiochip0", "tilt"),
                     {{"lines", "17"}},
                     "option lines needs two offsets"});
    cases.push_back({"gpio",
                     described("config", "/dev/gpiochip0", "tilt"),
                     {{"lines", "17,27"}, {"table", "upright,left,right"}},
                     "table needs four orientations"});
    cases.push_back(
        {"gpio", described("config", "/dev/gpiochip0", "tilt"), {}, "option lines is required"});
  }
  for (auto& c : cases) {
    SCOPED_TRACE(c.message);
    auto driver = registry.find(PROCAM_FAMILY_TILT, c.driver);
    ASSERT_TRUE(driver);
    Options o(c.options);
    procam_device out{};
    char err[256] = {};
    const int status = driver->factory->create(&c.desc.view(), &o.config, &out, err, sizeof err);
    EXPECT_EQ(status, PROCAM_EINVAL) << err;
    EXPECT_NE(std::string(err).find(c.message), std::string::npos) << err;
    EXPECT_EQ(out.destroy, nullptr);
  }
  // A device that is not there is ENODEV, named.
  auto i2c = registry.find(PROCAM_FAMILY_TILT, "i2c");
  auto absent = described("config", "/nonexistent/i2c-9", "tilt");
  Options o(Kv{{"chip", "adxl345"}});
  procam_device out{};
  char err[256] = {};
  EXPECT_EQ(i2c->factory->create(&absent.view(), &o.config, &out, err, sizeof err), PROCAM_ENODEV);
  EXPECT_NE(std::string(err).find("/nonexistent/i2c-9"), std::string::npos) << err;
}

TEST(TiltPlugin, I2cReadsRegistersAndRejectsGarbage) {
  auto bus = std::make_shared<FakeI2cBus>();
  FakeChip chip = mpu6050();
  bus->chips.push_back(&chip);
  auto desc = described("config", "/dev/i2c-1", "tilt");
  Options o(Kv{{"chip", "mpu6050"}, {"range_g", "4"}, {"stuck_limit", "3"}});
  procam_device raw{};
  char err[256] = {};
  auto dev =
      own(plugin::createI2cOn(bus, &desc.view(), &o.config, &raw, err, sizeof err), raw, err);
  ASSERT_TRUE(dev.valid());
  EXPECT_EQ(dev.pollFd(), -1);            // polled by timer
  EXPECT_EQ(chip.lastWrite(0x1C), 0x08);  // ACCEL_CONFIG: ±4 g

  EXPECT_EQ(readOnce(dev).status, PROCAM_EAGAIN);  // data not ready: no blocking wait
  // ±4 g: 8192 counts per g, big-endian. (0.5, -0.25, 0.75) g: |f| = 0.935 g.
  // The gyroscope's (131, 0, -655) counts at 65.5 LSB/(deg/s): 2, 0, -10 deg/s.
  const auto gyro = bigEndian({131, 0, -655});
  for (int i = 0; i < 6; ++i) chip.regs[std::size_t(0x43 + i)] = gyro[std::size_t(i)];
  chip.produce(bigEndian({4096, -2048, 6144}));
  Read r = readOnce(dev);
  ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
  EXPECT_NEAR((force(r) - Vec3(0.5, -0.25, 0.75) * kG).norm(), 0, 1e-12);
  // Its gyroscope's reading with that sample, through the ABI (tilt table version 3).
  const auto rate = plugins::tiltRate(dev.raw());
  ASSERT_TRUE(rate);
  EXPECT_NEAR(rate->angular_velocity[0], 2 * M_PI / 180, 1e-12);
  EXPECT_NEAR(rate->angular_velocity[2], -10 * M_PI / 180, 1e-12);
  EXPECT_EQ(rate->timestamp_ns, r.sample.timestamp_ns);

  // (2, 2, 2.5) g, |f| = 3.8 g: shaken, rejected and counted.
  chip.produce(bigEndian({16384, 16384, 20480}));
  r = readOnce(dev);
  EXPECT_TRUE(r.rejected()) << r.reason;
  // The same vector three times in a row (stuck_limit 3): the third is stuck.
  const auto frozen = bigEndian({0, 0, 8192});
  for (int i = 0; i < 2; ++i) {
    chip.produce(frozen);
    EXPECT_EQ(readOnce(dev).status, PROCAM_OK);
  }
  chip.produce(frozen);
  r = readOnce(dev);
  EXPECT_TRUE(r.rejected()) << r.reason;
  EXPECT_NE(r.reason.find("stuck"), std::string::npos);
  const procam_tilt_counts c = counts(dev);
  EXPECT_EQ(c.accepted, 3u);
  EXPECT_EQ(c.bad_norm, 1u);
  EXPECT_EQ(c.stuck, 1u);

  bus->stuck = true;  // SDA held low
  EXPECT_EQ(readOnce(dev).status, PROCAM_EIO);
  bus->stuck = false;
  bus->chips.clear();  // the chip stops acknowledging
  r = readOnce(dev);
  EXPECT_EQ(r.status, PROCAM_EIO);
  EXPECT_NE(r.reason.find("stopped acknowledging"), std::string::npos) << r.reason;
}

TEST(TiltPlugin, I2cWrongIdentityIsNoDevice) {
  auto bus = std::make_shared<FakeI2cBus>();
  FakeChip chip = adxl345();
  chip.regs[0x00] = 0x00;
  bus->chips.push_back(&chip);
  auto desc = described("config", "/dev/i2c-1", "tilt");
  Options o(Kv{{"chip", "adxl345"}});
  procam_device raw{};
  char err[256] = {};
  EXPECT_EQ(plugin::createI2cOn(bus, &desc.view(), &o.config, &raw, err, sizeof err),
            PROCAM_ENODEV);
  EXPECT_NE(std::string(err).find("identity register"), std::string::npos) << err;
}

TEST(TiltPlugin, IioThroughSysfsRootCountsGarbage) {
  FakeIioTree tree;
  tree.set("in_accel_x_raw", "0");
  tree.set("in_accel_y_raw", "-1000");
  tree.set("in_accel_z_raw", "0");
  tree.set("in_accel_scale", "0.00980665");  // 1 mg per count
  auto desc = described("iio", "/dev/iio:device0", "tilt");
  plugins::DriverRegistry registry;
  std::vector<std::string> refused;
  registry.addAll(staticDrivers(), refused);
  auto iio = registry.find(PROCAM_FAMILY_TILT, "iio");
  ASSERT_TRUE(iio);
  auto dev = plugins::createDevice(*iio, desc,
                                   {{"sysfs_root", tree.root().string()}, {"buffered", "false"}});
  ASSERT_TRUE(dev) << dev.error().message;
  EXPECT_EQ(dev->pollFd(), -1);  // sysfs polling
  Read r = readOnce(*dev);
  ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
  EXPECT_NEAR((force(r) - Vec3(0, -kG, 0)).norm(), 0, 1e-12);

  tree.set("in_accel_x_raw", "nan");
  EXPECT_TRUE(readOnce(*dev).rejected());
  tree.set("in_accel_x_raw", "20000");  // 20 g: beyond the gate's 16 g
  EXPECT_TRUE(readOnce(*dev).rejected());
  tree.set("in_accel_x_raw", "0");
  tree.set("in_accel_y_raw", "-100");  // 0.1 g: free fall or a dropped sample
  r = readOnce(*dev);
  EXPECT_TRUE(r.rejected());
  EXPECT_NE(r.reason.find("far from 1 g"), std::string::npos) << r.reason;
  const procam_tilt_counts c = counts(*dev);
  EXPECT_EQ(c.accepted, 1u);
  EXPECT_EQ(c.not_finite, 1u);
  EXPECT_EQ(c.out_of_range, 1u);
  EXPECT_EQ(c.bad_norm, 1u);
  EXPECT_EQ(plugins::rejectedSamples(c), 3u);
}

TEST(TiltPlugin, HidStoredReportsAndLogicalRange) {
  auto t = std::make_unique<ScriptedHid>();
  t->descriptor = hubDescriptor();                 // 0.01 g per unit
  t->reports.push_back({0x04, 1, 2, 3, 4, 5, 6});  // gyro: skipped
  t->reports.push_back(accelReport(0, 0, -100));
  t->reports.push_back(accelReport(-32768, 0, 0));  // outside the logical range
  Options o;
  procam_device raw{};
  char err[256] = {};
  auto dev = own(plugin::createHidOn(std::move(t), &o.config, &raw, err, sizeof err), raw, err);
  ASSERT_TRUE(dev.valid());
  Read r = readOnce(dev);
  ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
  EXPECT_NEAR((force(r) - Vec3(0, 0, -kG)).norm(), 0, 1e-12);
  EXPECT_TRUE(readOnce(dev).rejected());
  EXPECT_EQ(readOnce(dev).status, PROCAM_EAGAIN);  // nothing queued
  EXPECT_EQ(counts(dev).out_of_range, 1u);

  auto foreign = std::make_unique<ScriptedHid>();
  foreign->descriptor = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0xC0};  // a mouse, empty
  EXPECT_EQ(plugin::createHidOn(std::move(foreign), &o.config, &raw, err, sizeof err),
            PROCAM_ENODEV);
}

TEST(TiltPlugin, GpioDebouncedOrientationIsNeverStuck) {
  auto lines = std::make_unique<ScriptedLines>();
  ScriptedLines* script = lines.get();
  Options o(Kv{{"debounce_ms", "10"}, {"tilt_deg", "30"}});
  procam_device raw{};
  char err[256] = {};
  auto dev =
      own(plugin::createGpioOn(std::move(lines), &o.config, &raw, err, sizeof err), raw, err);
  ASSERT_TRUE(dev.valid());
  for (int i = 0; i < 100; ++i) {  // the same nominal vector every time: not "stuck"
    Read r = readOnce(dev);
    ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
    EXPECT_NEAR((force(r) - Vec3(0, -kG, 0)).norm(), 0, 1e-12);
  }
  // Line 1 falls: tilted left once 10 ms have passed without bounce.
  script->edges = {{1, false, script->now}};
  EXPECT_NEAR(force(readOnce(dev)).y(), -kG, 1e-12);  // not settled yet
  script->now += 11 * kMs;
  Read r = readOnce(dev);
  ASSERT_EQ(r.status, PROCAM_OK);
  EXPECT_NEAR(force(r).x(), kG * 0.5, 1e-12);  // sin 30°
  EXPECT_NEAR(force(r).norm(), kG, 1e-12);
}

TEST(TiltPlugin, LoadableObjectThroughTheLoader) {
  auto drivers = plugins::loadSharedPlugin(PROCAM_TILT_PLUGIN_PATH);
  ASSERT_TRUE(drivers) << drivers.error().message;
  ASSERT_EQ(drivers->size(), PROCAM_TILT_GPIOD ? 4u : 3u);
  const plugins::Driver* iio = nullptr;
  for (const auto& d : *drivers)
    if (d.name() == "iio") iio = &d;
  ASSERT_NE(iio, nullptr);
  EXPECT_EQ(iio->origin, PROCAM_TILT_PLUGIN_PATH);

  FakeIioTree tree;
  tree.set("in_accel_x_raw", "500");
  tree.set("in_accel_y_raw", "-866");
  tree.set("in_accel_z_raw", "0");
  tree.set("in_accel_scale", "0.00980665");
  auto desc = described("iio", "/dev/iio:device0", "tilt");
  EXPECT_EQ(iio->factory->probe(&desc.view()), 60);
  auto dev =
      plugins::createDevice(*iio, desc, {{"device_dir", tree.dir().string()}, {"buffered", "0"}});
  ASSERT_TRUE(dev) << dev.error().message;
  Read r = readOnce(*dev);
  ASSERT_EQ(r.status, PROCAM_OK) << r.reason;
  EXPECT_NEAR((force(r) - Vec3(0.5, -0.866, 0) * kG).norm(), 0, 1e-12);
}

}  // namespace
}  // namespace procam::tilt
