// The sensor side of automatic keystone (keystone/tilt_tracker.hpp): calibration,
// low-pass, stillness and hysteresis of gated accelerometer samples, and the raw mean
// of a still hold that the six-position calibration takes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>

#include "core/units.hpp"
#include "keystone/orientation.hpp"
#include "keystone/tilt_tracker.hpp"

namespace procam::keystone {
namespace {

// The handheld scene's MPU-6050 mount: chip x right, y forward, z up.
Mat3 handheldMount() {
  Mat3 M;
  M << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return M;
}

// A still reading (m/s^2) for gravity `down` (projector frame) through the mount,
// with a sensor offset (g).
Vec3 reading(const Mat3& sensor_from_projector, const Vec3& down, const Vec3& offset) {
  return (sensor_from_projector * (-down) + offset) * kStandardGravity;
}

std::uint64_t ns(double t) {
  return static_cast<std::uint64_t>(t * 1e9);
}

double angle(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(TiltTracker, CalibratedStillReadingsGiveTheTrueGravityAndFewUpdates) {
  TiltMount mount;
  mount.sensor_from_projector = handheldMount();
  const Vec3 offset(0.05, -0.05, 0.05);  // the scene's bias, in g
  mount.calibration.offset = offset;
  auto tracker = TiltTracker::create({}, mount);
  ASSERT_TRUE(tracker) << tracker.error().message;
  const Vec3 down = rotationFromAngles({12 * kDeg, -7 * kDeg, 0}) * Vec3(0, 0, -1);  // world -Z
  int published = 0;
  std::optional<Vec3> last;
  for (int k = 0; k < 2000; ++k) {  // 20 s at 100 Hz
    if (auto d = tracker->add(reading(mount.sensor_from_projector, down, offset), ns(0.01 * k))) {
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
  auto tracker = TiltTracker::create({}, TiltMount{});
  ASSERT_TRUE(tracker);
  const Vec3 down(0, 1, 0);
  ASSERT_TRUE(tracker->add(reading(Mat3::Identity(), down, Vec3::Zero()), ns(1.0)));
  // The same timestamp again (a timer faster than the sensor): ignored.
  EXPECT_FALSE(tracker->add(reading(Mat3::Identity(), Vec3(1, 0, 0), Vec3::Zero()), ns(1.0)));
  Vec3 nan = reading(Mat3::Identity(), down, Vec3::Zero());
  nan.x() = NAN;
  EXPECT_FALSE(tracker->add(nan, ns(1.01)));
  // The next good sample, turned by 10 degrees, moves the estimate part of the way
  // (a 10 Hz low-pass over 10 ms) and it stays finite.
  const Vec3 turned(0, std::cos(10 * kDeg), -std::sin(10 * kDeg));
  auto next = tracker->add(reading(Mat3::Identity(), turned, Vec3::Zero()), ns(1.02));
  ASSERT_TRUE(next);
  EXPECT_TRUE(next->allFinite());
  EXPECT_GT(angle(*next, down), 1 * kDeg);
  EXPECT_LT(angle(*next, down), 9 * kDeg);
}

TEST(TiltTracker, StillMeanIsTheRawReading) {
  TiltMount mount;
  mount.calibration.offset = Vec3(0.1, 0, 0);  // applied to the filter, not to the mean
  auto tracker = TiltTracker::create({}, mount);
  ASSERT_TRUE(tracker);
  const Vec3 raw(0.1, 0.2, 0.98);
  for (int k = 0; k < 100; ++k) tracker->add(raw * kStandardGravity, ns(0.01 * k));
  auto mean = tracker->stillMean();
  ASSERT_TRUE(mean);
  EXPECT_LT((mean->first - raw).norm(), 1e-12);
  EXPECT_GT(mean->second, 50);
}

}  // namespace
}  // namespace procam::keystone
