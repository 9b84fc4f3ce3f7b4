// Scene::at(t): trajectories (slerp), rigid attachments, the accelerometer's
// specific force, bias and white noise, and the tracker's noise (handheld, dome3).
#include <gtest/gtest.h>

#include <cmath>

#include "core/units.hpp"
#include "geometry/yaw_pitch_roll.hpp"
#include "sim/scene_library.hpp"
#include "sim/sensors.hpp"
#include "sim/trajectory.hpp"

namespace procam::sim {
namespace {

Vec3 forward(const geom::Pose& pose) {
  return pose.R.row(2).transpose();
}

TEST(SimTime, HandheldTrajectoryHitsItsKeyframesAndSlerpsBetween) {
  auto scene = resolveScene("handheld");
  ASSERT_TRUE(scene) << scene.error().message;
  const double s45 = std::sqrt(0.5);
  // t = 1: pitch +45 degrees.
  EXPECT_TRUE(forward(scene->at(1.0).projectors[0].model.pose).isApprox(Vec3(0, s45, s45), 1e-12));
  // Halfway between level and pitch +45 about a single axis: pitch 22.5 degrees.
  const double h = degToRad(22.5);
  EXPECT_TRUE(forward(scene->at(0.5).projectors[0].model.pose)
                  .isApprox(Vec3(0, std::cos(h), std::sin(h)), 1e-12));
  // t = 4: yaw +30 (turned right, towards +X).
  const double y = degToRad(30);
  EXPECT_TRUE(forward(scene->at(4.0).projectors[0].model.pose)
                  .isApprox(Vec3(std::sin(y), std::cos(y), 0), 1e-12));
  // Before the first and after the last keyframe the end poses hold.
  EXPECT_TRUE(
      scene->at(-3).projectors[0].model.pose.R.isApprox(scene->at(0).projectors[0].model.pose.R));
  EXPECT_TRUE(
      scene->at(99).projectors[0].model.pose.R.isApprox(scene->at(8).projectors[0].model.pose.R));
  EXPECT_TRUE(scene->at(2.7).projectors[0].model.pose.center().isApprox(Vec3(0, 0, 1.2)));
}

TEST(SimTime, SmoothEasingIsTheMinimumJerkProfileOfAHand) {
  // Level to yaw 60 degrees in 1 s: s(u) = 10u^3 - 15u^4 + 6u^5 of the segment's time
  // fraction u (minimum jerk).
  std::vector<Keyframe> keys(2);
  keys[0].time = 0;
  keys[1].time = 1;
  keys[0].orientation = Eigen::Quaterniond::Identity();
  keys[1].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(degToRad(60), Vec3::UnitZ()));
  auto traj = Trajectory::create("turn", keys, false, Easing::kSmooth);
  ASSERT_TRUE(traj);
  auto yawAt = [&](double t) { return Eigen::AngleAxisd(traj->poseAt(t).R.transpose()).angle(); };
  EXPECT_NEAR(yawAt(0.25), degToRad(60) * 0.103515625, 1e-12);
  EXPECT_NEAR(yawAt(0.5), degToRad(30), 1e-12);
  // At rest at both keyframes (speed 30 u^2 (1 - u)^2 60 deg/s: 0.0006 deg/s over the
  // first ms), 112.5 deg/s, 1.875 times the linear speed, halfway.
  const double h = 1e-3;
  EXPECT_LT(radToDeg(yawAt(h) - yawAt(0)) / h, 0.01);
  EXPECT_LT(radToDeg(yawAt(1) - yawAt(1 - h)) / h, 0.01);
  EXPECT_NEAR(radToDeg(yawAt(0.5 + h) - yawAt(0.5 - h)) / (2 * h), 112.5, 1e-3);
  // Linear easing: 60 deg/s from the start.
  auto linear = Trajectory::create("turn", keys, false);
  ASSERT_TRUE(linear);
  EXPECT_NEAR(Eigen::AngleAxisd(linear->poseAt(0.25).R.transpose()).angle(), degToRad(15), 1e-12);
}

TEST(SimTime, AttachedCameraMovesRigidlyWithItsProjector) {
  auto scene = resolveScene("handheld");
  ASSERT_TRUE(scene);
  for (const double t : {0.0, 0.37, 1.0, 3.3, 5.5, 7.9}) {
    const SceneState s = scene->at(t);
    const geom::Pose& p = s.projectors[0].model.pose;
    const geom::Pose& c = s.cameras[0].model.pose;
    // camera <- projector, constant: 6 cm to the right, toed in (yaw -3: turned 3 degrees
    // to the left, towards the projector's optical axis).
    const Mat3 R_cp = c.R * p.R.transpose();
    const Vec3 cam_in_proj = p.toDevice(c.center());
    EXPECT_TRUE(cam_in_proj.isApprox(Vec3(0.06, 0, 0), 1e-12)) << t;
    EXPECT_TRUE(R_cp.transpose().isApprox(geom::parentFromChild({0, 0, degToRad(-3)}), 1e-12)) << t;
  }
}

TEST(SimTilt, AccelerometerReportsGravityReactionInItsMountedFrame) {
  auto scene = resolveScene("handheld");
  ASSERT_TRUE(scene);
  const double g = kStandardGravity, s45 = std::sqrt(0.5);
  // Level: the chip's z (projector up) carries +1 g.
  auto level = sampleTilt(*scene, "accel", 0.0, 1, false);
  ASSERT_TRUE(level);
  EXPECT_TRUE(level->truth.isApprox(Vec3(0, 0, g), 1e-12));
  // Bias is added in milli-g per axis.
  EXPECT_TRUE((level->value - level->truth).isApprox(g * 1e-3 * Vec3(50, -50, 50), 1e-12));
  // Nose up 45 degrees: gravity reaction splits between chip y (forward) and z (up).
  auto up = sampleTilt(*scene, "accel", 1.0, 1, false);
  ASSERT_TRUE(up);
  EXPECT_TRUE(up->truth.isApprox(Vec3(0, g * s45, g * s45), 1e-12));
  // Roll +20 (right side down): chip x sees -g sin(20).
  auto roll = sampleTilt(*scene, "accel", 5.0, 1, false);
  ASSERT_TRUE(roll);
  const double r = degToRad(20);
  EXPECT_TRUE(roll->truth.isApprox(Vec3(-g * std::sin(r), 0, g * std::cos(r)), 1e-12));
}

// White noise sigma = density * sqrt(rate / 2) per axis, within 5% (the simulator's
// noise fidelity bound),
// zero mean after the bias; samples repeat exactly for the same seed.
TEST(SimTilt, NoiseMatchesTheNoiseDensity) {
  auto scene = resolveScene("handheld");
  ASSERT_TRUE(scene);
  const auto& spec = scene->tiltSensors().at(0);
  auto series = sampleTiltSeries(*scene, "accel", 0.0, 80.0, 3);  // 8001 samples at 100 Hz
  ASSERT_TRUE(series);
  ASSERT_EQ(series->size(), 8001u);
  const double sigma_model =
      spec.noise_density_ug * 1e-6 * std::sqrt(spec.rate_hz / 2) * kStandardGravity;  // m/s^2
  const Vec3 bias = 1e-3 * kStandardGravity * spec.bias_mg;
  Vec3 sum = Vec3::Zero(), sum_sq = Vec3::Zero();
  for (const auto& s : *series) {
    const Vec3 e = s.value - s.truth - bias;
    sum += e;
    sum_sq += e.cwiseProduct(e);
  }
  const double n = static_cast<double>(series->size());
  for (int a = 0; a < 3; ++a) {
    const double mean = sum[a] / n;
    const double sigma = std::sqrt(sum_sq[a] / n - mean * mean);
    EXPECT_NEAR(sigma, sigma_model, 0.05 * sigma_model) << "axis " << a;
    EXPECT_LT(std::abs(mean), 4 * sigma_model / std::sqrt(n)) << "axis " << a;
  }
  auto again = sampleTilt(*scene, "accel", (*series)[1234].time, 3);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->value, (*series)[1234].value);
}

TEST(SimTilt, FullScaleClampsAndUnitsOfG) {
  auto scene = Scene::parse(R"(
[[projectors]]
name = "p"
resolution = [64, 48]
intrinsics = { hfov_deg = 40.0 }
pose = { position = [0.0, 0.0, 1.0] }
[[tilt_sensors]]
name = "a"
attached_to = "p"
bias_mg = 700.0
full_scale_g = 1.5
units = "g"
)",
                            "clamp.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  // Level projector, identity mount: +1 g along the projector's up, which is -y.
  auto s = sampleTilt(*scene, "a", 0.0, 1, false);
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->truth.isApprox(Vec3(0, -1, 0)));
  EXPECT_TRUE(s->value.isApprox(Vec3(0.7, -0.3, 0.7)));
  auto clamped = Scene::parse(R"(
[[projectors]]
name = "p"
resolution = [64, 48]
intrinsics = { hfov_deg = 40.0 }
pose = { position = [0.0, 0.0, 1.0], pitch_deg = 90.0 }
[[tilt_sensors]]
name = "a"
attached_to = "p"
bias_mg = 700.0
full_scale_g = 1.5
units = "g"
)",
                              "clamp.toml", {});
  ASSERT_TRUE(clamped);
  // Looking straight up: +1 g along the projector's z; 1.7 g clamps to 1.5 g.
  auto c = sampleTilt(*clamped, "a", 0.0, 1, false);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->value.z(), 1.5, 1e-12);
}

TEST(SimTracker, ReportsTheViewerWithItsNoise) {
  auto scene = resolveScene("dome3");
  ASSERT_TRUE(scene);
  // The walk loops with period 8 s; t = 2 s is halfway between x = -0.6 and 0.6.
  EXPECT_TRUE(scene->viewerPosition(2.0).isApprox(Vec3(0, -0.8, 1.65), 1e-12));
  EXPECT_TRUE(scene->viewerPosition(10.0).isApprox(scene->viewerPosition(2.0), 1e-12));
  const auto& spec = scene->trackers().at(0);
  double sum_sq = 0;
  int n = 0;
  for (int k = 0; k < 3000; ++k) {
    auto s = sampleTracker(*scene, spec.name, k / spec.rate_hz, 5);
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->truth.isApprox(scene->viewerPosition(s->time), 1e-12));
    sum_sq += (s->position - s->truth).squaredNorm();
    n += 3;
  }
  const double sigma = std::sqrt(sum_sq / n);
  EXPECT_NEAR(sigma, spec.noise_sigma_m, 0.05 * spec.noise_sigma_m);
}

}  // namespace
}  // namespace procam::sim
