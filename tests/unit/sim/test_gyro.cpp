// The virtual rig's gyroscope and the accelerometer's view of motion: angular velocity
// from the trajectory, white noise, constant bias and bias walk against their model,
// and the specific force of a projector that changes speed.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "sim/scene.hpp"
#include "sim/sensors.hpp"

namespace procam::sim {
namespace {

// A projector yawing 90 degrees in 2 s (slerp: constant rate), then sliding 1 m to the
// right in 1 s and stopping; a tilt sensor with a gyroscope on it (chip axes = projector
// right, forward, up, as an MPU-6050 on the board).
std::string turningScene(const std::string& gyro) {
  return R"([scene]
name = "turning"

[[trajectories]]
name = "turn"
keyframes = [
  { t = 0.0, position = [0.0, 0.0, 1.0], yaw_deg = 0.0 },
  { t = 2.0, position = [0.0, 0.0, 1.0], yaw_deg = 90.0 },
  { t = 3.0, position = [1.0, 0.0, 1.0], yaw_deg = 90.0 },
  { t = 4.0, position = [1.0, 0.0, 1.0], yaw_deg = 90.0 },
]

[[projectors]]
name = "proj"
resolution = [640, 400]
intrinsics = { fx = 800.0, fy = 800.0, cx = 319.5, cy = 199.5 }
trajectory = "turn"

[[tilt_sensors]]
name = "imu"
attached_to = "proj"
mount_matrix = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]
rate_hz = 200.0
)" + gyro;
}

TEST(SimGyro, AngularVelocityNoiseBiasAndWalkFollowTheirModel) {
  auto scene = Scene::parse(
      turningScene(
          R"(gyro = { noise_density_dps = 0.01, bias_dps = [0.5, -0.2, 0.1], bias_walk_dps = 0.002 }
)"),
      "turning.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  // Turning at 45 deg/s about world up: the chip's z axis is the projector's up, so the
  // gyro reads the turn on z alone (positive yaw turns the optical axis right: clockwise
  // seen from above, a negative turn about up).
  auto turning = sampleGyro(*scene, "imu", 1.0, 1, false);
  ASSERT_TRUE(turning) << turning.error().message;
  const Vec3 rate = turning->truth;
  EXPECT_NEAR(radToDeg(rate.z()), -45.0, 1e-6);
  EXPECT_NEAR(rate.head<2>().norm(), 0, 1e-9);
  EXPECT_LT((turning->value - rate - turning->bias).norm(), 1e-12);  // no noise asked
  EXPECT_LT((turning->bias - degToRad(1.0) * Vec3(0.5, -0.2, 0.1)).norm(), 1e-3);
  // Still: only bias and noise. White noise sigma = density sqrt(rate / 2) per axis.
  double sq = 0;
  int n = 0;
  for (int k = 0; k < 5000; ++k) {
    auto s = sampleGyro(*scene, "imu", 4.0 + k / 200.0, 7, true);
    ASSERT_TRUE(s);
    EXPECT_LT(s->truth.norm(), 1e-12);
    const Vec3 e = s->value - s->bias;
    sq += e.squaredNorm();
    n += 3;
  }
  const double sigma = degToRad(0.01) * std::sqrt(100.0);
  EXPECT_NEAR(std::sqrt(sq / n) / sigma, 1.0, 0.03);  // 15000 draws: 0.6 % standard error
  // The bias walk: after t seconds its spread is bias_walk sqrt(t) per axis.
  double walk_sq = 0;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    auto s = sampleGyro(*scene, "imu", 10.0, seed, false);
    ASSERT_TRUE(s);
    walk_sq += (s->bias - degToRad(1.0) * Vec3(0.5, -0.2, 0.1)).squaredNorm();
  }
  const double walk_sigma = degToRad(0.002) * std::sqrt(10.0);
  EXPECT_NEAR(std::sqrt(walk_sq / 180) / walk_sigma, 1.0, 0.2);  // 180 draws: 5 % error
  // The same sample whoever asks, in any order.
  auto again = sampleGyro(*scene, "imu", 1.0, 1, false);
  EXPECT_EQ(again->value, turning->value);
}

TEST(SimGyro, TheAccelerometerFeelsTheProjectorSpeedUpAndStop) {
  auto scene = Scene::parse(turningScene(""), "turning.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  // Between t = 2 and 3 s the projector moves at 1 m/s; the specific force's motion part
  // integrated over the start and over the stop is +1 and -1 m/s along the motion (world
  // +x, the projector's forward after its quarter turn: the chip's y).
  double start = 0, stop = 0;
  for (int k = 1; k < 800; ++k) {
    const double t = k / 200.0;
    auto s = sampleTilt(*scene, "imu", t, 1, false);
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->truth.z(), kStandardGravity, 1e-6);  // level: gravity on the chip's z
    if (t < 2.5) start += s->motion.y() / 200.0;
    if (t > 2.5) stop += s->motion.y() / 200.0;
    if (std::abs(t - 2.0) > 0.011 && std::abs(t - 3.0) > 0.011) {
      EXPECT_LT(s->motion.norm(), 1e-6) << t;  // steady motion: nothing but gravity
    }
  }
  EXPECT_NEAR(start, 1.0, 1e-6);
  EXPECT_NEAR(stop, -1.0, 1e-6);
  // A sensor without a gyroscope has none to sample.
  EXPECT_EQ(sampleGyro(*scene, "imu", 1.0).error().code, ErrorCode::kNotFound);
}

TEST(SimGyro, BadGyroTablesAreRefused) {
  for (const std::string& bad :
       {std::string("gyro = { noise_density_dps = -1.0 }\n"),
        std::string("gyro = { bias_walk_dps = 1000.0 }\n"), std::string("gyro = { spin = 1.0 }\n"),
        std::string("gyro = 3\n")}) {
    auto scene = Scene::parse(turningScene(bad), "bad.toml", {});
    ASSERT_FALSE(scene) << bad;
    EXPECT_EQ(scene.error().code, ErrorCode::kParse);
  }
}

}  // namespace
}  // namespace procam::sim
