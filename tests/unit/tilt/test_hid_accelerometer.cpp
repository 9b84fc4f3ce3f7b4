#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <deque>
#include <thread>

#include "fake_hid.hpp"
#include "tilt/hid/hid_accelerometer.hpp"

namespace procam::tilt {
namespace {

using namespace testing;

TEST(HidDescriptor, FieldsOffsetsRangesAndExponent) {
  auto d = parseHidDescriptor(hubDescriptor());
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_TRUE(d->uses_report_ids);
  auto a = findAccelerometer(*d);
  ASSERT_TRUE(a) << a.error().message;
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(a->axis[i].report_id, 3);
    EXPECT_EQ(a->axis[i].bit_offset, std::uint32_t(16 * i));
    EXPECT_EQ(a->axis[i].bit_size, 16u);
    EXPECT_EQ(a->axis[i].logical_min, -32767);
    EXPECT_EQ(a->axis[i].logical_max, 32767);
    EXPECT_EQ(a->axis[i].unit_exponent, -2);
  }
  EXPECT_NEAR(a->scale, 0.01 * kStandardGravity, 1e-15);
  // The gyro's range was written as 0x26 0xFF 0xFF with a minimum of 0: 65535.
  bool gyro = false;
  for (const HidField& f : d->inputs)
    if (f.usage == 0x457) {
      gyro = true;
      EXPECT_EQ(f.logical_max, 65535);
      EXPECT_EQ(f.report_id, 4);
    }
  EXPECT_TRUE(gyro);
}

TEST(HidAccelerometer, DecodesReportsAndSkipsOtherSensors) {
  auto t = std::make_unique<ScriptedHid>();
  t->descriptor = hubDescriptor();
  t->reports.push_back({0x04, 1, 2, 3, 4, 5, 6});  // gyro report: skipped
  t->reports.push_back(accelReport(50, -25, -100));
  t->reports.push_back(accelReport(-32768, 0, 0));  // outside the logical range
  HidAccelerometer sensor(std::move(t));
  ASSERT_TRUE(sensor.open());
  auto s = sensor.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR((s->specific_force - Vec3(0.5, -0.25, -1.0) * kStandardGravity).norm(), 0, 1e-12);
  EXPECT_EQ(sensor.read().error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(sensor.read().error().code, ErrorCode::kNotFound);
}

TEST(HidAccelerometer, SiUnitWithOtherExponent) {
  auto t = std::make_unique<ScriptedHid>();
  t->descriptor = hubDescriptor(0x0D, true);  // 10^-3 m/s^2
  t->reports.push_back(accelReport(9807, 0, -4903));
  HidAccelerometer sensor(std::move(t));
  ASSERT_TRUE(sensor.open());
  auto s = sensor.read();
  ASSERT_TRUE(s);
  EXPECT_NEAR((s->specific_force - Vec3(9.807, 0, -4.903)).norm(), 0, 1e-12);
}

TEST(HidDescriptor, GyrometerFieldsAndUnits) {
  auto d = parseHidDescriptor(hubDescriptor(0x0E, false, true));
  ASSERT_TRUE(d) << d.error().message;
  auto g = findGyrometer(*d);
  ASSERT_TRUE(g) << g.error().message;
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(g->axis[i].report_id, 4);
    EXPECT_EQ(g->axis[i].usage, 0x457 + i);
    EXPECT_EQ(g->axis[i].bit_offset, std::uint32_t(16 * i));
    EXPECT_EQ(g->axis[i].logical_min, -32767);
  }
  // Degrees per second (the default unit) times 10^-2.
  EXPECT_NEAR(g->scale, 0.01 * M_PI / 180, 1e-15);
  // Radians per second; the usage tables' and Linux's codes for degrees per second.
  for (auto [unit, scale] : {std::pair<std::uint16_t, double>{0xF012, 0.01},
                             {0xF014, 0.01 * M_PI / 180},
                             {0x0015, 0.01 * M_PI / 180}}) {
    auto u = parseHidDescriptor(hubDescriptor(0x0E, false, true, unit));
    ASSERT_TRUE(u);
    auto f = findGyrometer(*u);
    ASSERT_TRUE(f) << unit;
    EXPECT_NEAR(f->scale, scale, 1e-15) << unit;
  }
  auto odd = parseHidDescriptor(hubDescriptor(0x0E, false, true, 0x1A));  // g: not a rate
  ASSERT_TRUE(odd);
  EXPECT_EQ(findGyrometer(*odd).error().code, ErrorCode::kInvalidInput);
  // The accelerometer alone (the mouse below has neither).
  const std::vector<std::uint8_t> mouse = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0xC0};
  EXPECT_EQ(findGyrometer(*parseHidDescriptor(mouse)).error().code, ErrorCode::kNotFound);
}

TEST(HidAccelerometer, ASensorHubsGyrometerComesWithEachSample) {
  auto t = std::make_unique<ScriptedHid>();
  ScriptedHid& hub = *t;
  t->descriptor = hubDescriptor(0x0E, false, true);
  t->reports.push_back(accelReport(0, 0, 100));  // before any gyrometer report: no rate
  t->reports.push_back(gyroReport(1000, -2000, 50));
  t->reports.push_back(accelReport(0, 0, 100));
  HidAccelerometer sensor(std::move(t));
  ASSERT_TRUE(sensor.open());
  EXPECT_TRUE(sensor.hasGyroscope());
  auto first = sensor.read();
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_FALSE(first->angular_velocity);
  auto s = sensor.read();
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_TRUE(s->angular_velocity);
  const double k = 0.01 * M_PI / 180;  // rad/s per unit
  EXPECT_NEAR((*s->angular_velocity - Vec3(10, -20, 0.5) * 100 * k).norm(), 0, 1e-12);
  // A gyrometer gone quiet for longer than kGyroFreshNs: samples come without a rate.
  std::this_thread::sleep_for(std::chrono::nanoseconds(HidAccelerometer::kGyroFreshNs) +
                              std::chrono::milliseconds(20));
  hub.reports.push_back(accelReport(0, 0, 100));
  auto stale = sensor.read();
  ASSERT_TRUE(stale);
  EXPECT_FALSE(stale->angular_velocity);
  // Out of its range: the rate is dropped, the accelerometer's sample kept.
  hub.reports.push_back(gyroReport(1000, 0, 0));
  hub.reports.push_back(accelReport(0, 0, 100));
  auto fresh = sensor.read();
  ASSERT_TRUE(fresh && fresh->angular_velocity);
  hub.reports.push_back(gyroReport(-32768, 0, 0));
  hub.reports.push_back(accelReport(0, 0, 100));
  auto dropped = sensor.read();
  ASSERT_TRUE(dropped) << dropped.error().message;
  EXPECT_FALSE(dropped->angular_velocity);
}

TEST(HidAccelerometer, AGyrometerItCannotReadLeavesTheAccelerometer) {
  auto t = std::make_unique<ScriptedHid>();
  t->descriptor = hubDescriptor(0x0E, false, true, 0x1A);  // a rate in g: not one
  t->reports.push_back(gyroReport(1000, 0, 0));
  t->reports.push_back(accelReport(0, 0, 100));
  HidAccelerometer sensor(std::move(t));
  ASSERT_TRUE(sensor.open());
  EXPECT_FALSE(sensor.hasGyroscope());
  auto s = sensor.read();
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_FALSE(s->angular_velocity);
  EXPECT_NEAR(s->specific_force.z(), kStandardGravity, 1e-12);
}

TEST(HidDescriptor, MalformedAndForeignDescriptors) {
  auto d = hubDescriptor();
  EXPECT_EQ(parseHidDescriptor(std::span(d).first(d.size() - 1)).error().code, ErrorCode::kParse);
  const std::vector<std::uint8_t> truncated = {0x05, 0x20, 0x27, 0xFF};
  EXPECT_EQ(parseHidDescriptor(truncated).error().code, ErrorCode::kParse);
  // A mouse: parses, but holds no accelerometer.
  const std::vector<std::uint8_t> mouse = {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x05, 0x01,
                                           0x09, 0x30, 0x09, 0x31, 0x15, 0x81, 0x25, 0x7F,
                                           0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xC0};
  auto m = parseHidDescriptor(mouse);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->inputs.size(), 2u);
  EXPECT_EQ(findAccelerometer(*m).error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace procam::tilt
