// The orientation the gyroscope carries while the hand turns the projector
// (keystone/gyro_orientation.hpp), on the virtual rig's handheld_tour trajectory: its
// gyroscope's readings integrated from the true orientation before a turn must end at
// the true orientation after it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "keystone/gyro_orientation.hpp"
#include "sim/scene_library.hpp"
#include "sim/sensors.hpp"

namespace procam::keystone {
namespace {

double angleBetween(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle();
}

struct Turn {
  Mat3 start, end;
  std::vector<std::pair<Vec3, std::uint64_t>> rates;  // projector frame
  std::vector<Vec3> downs;                            // true gravity, projector frame
};

// The readings of the tour's first turn (t = 10 to 11 s: yaw 30, pitch 45, roll 20 from
// level), noise-free or with the scene's noise, plus `bias` (rad/s, projector frame).
Turn firstTurn(bool noise, const Vec3& bias) {
  Turn turn;
  auto scene = sim::resolveScene("handheld_tour");
  EXPECT_TRUE(scene) << scene.error().message;
  const sim::TiltSensorSpec& spec = scene->tiltSensors().front();
  EXPECT_TRUE(spec.gyro);
  const Mat3 to_projector = spec.sensor_from_projector.transpose();
  turn.start = scene->at(9.99).projector("proj")->model.pose.R;
  turn.end = scene->at(11.01).projector("proj")->model.pose.R;
  for (int k = 999; k <= 1101; ++k) {
    const double t = k / spec.rate_hz;
    auto w = sim::sampleGyro(*scene, spec.name, t, 1, noise);
    EXPECT_TRUE(w);
    turn.rates.emplace_back(to_projector * (noise ? w->value : w->truth) + bias,
                            std::uint64_t(std::llround(t * 1e9)));
    turn.downs.push_back(scene->at(t).projector("proj")->model.pose.R * Vec3(0, 0, -1));
  }
  return turn;
}

TEST(GyroOrientation, IntegratedTurnEndsAtTheTrueOrientation) {
  const Turn turn = firstTurn(false, Vec3::Zero());
  ASSERT_GT(angleBetween(turn.start, turn.end), 0.9);  // a turn of over 50 degrees
  for (double gain : {0.0, 0.5}) {
    auto g = GyroOrientation::create({gain, 0.5});
    ASSERT_TRUE(g);
    g->start(turn.start, turn.rates.front().second, turn.rates.front().first);
    for (std::size_t i = 1; i < turn.rates.size(); ++i) {
      g->update(turn.rates[i].first, turn.downs[i], turn.rates[i].second);
    }
    const double error = angleBetween(g->R(), turn.end);
    std::printf("gravity gain %.1f: %.4f mrad after the turn\n", gain, error * 1e3);
    // The 100 Hz trapezoid against the smooth turn; 0.1 mrad is 0.14 px on a 1400 px lens.
    EXPECT_LT(error, 0.1e-3);
  }
}

TEST(GyroOrientation, PredictedToTheFrameOnTheWall) {
  // Each reading of the turn predicts the orientation 20 ms later (a frame drawn from it
  // reaches the wall then): against the truth at that time, at most 0.35 mrad (0.5 px on
  // a 1400 px lens) where the unpredicted orientation is off by the turn over 20 ms.
  const Turn turn = firstTurn(false, Vec3::Zero());
  auto scene = sim::resolveScene("handheld_tour");
  ASSERT_TRUE(scene);
  constexpr double kLead = 0.02;
  auto g = GyroOrientation::create({0.0, 0.5});
  ASSERT_TRUE(g);
  g->start(turn.start, turn.rates.front().second, turn.rates.front().first);
  double worst = 0, worst_unpredicted = 0;
  for (std::size_t i = 1; i < turn.rates.size(); ++i) {
    g->update(turn.rates[i].first, std::nullopt, turn.rates[i].second);
    const double t = static_cast<double>(turn.rates[i].second) * 1e-9 + kLead;
    const Mat3 truth = scene->at(t).projector("proj")->model.pose.R;
    worst = std::max(worst, angleBetween(g->predicted(kLead), truth));
    worst_unpredicted = std::max(worst_unpredicted, angleBetween(g->R(), truth));
  }
  std::printf("20 ms ahead: predicted %.3f mrad, unpredicted %.3f mrad at worst\n", worst * 1e3,
              worst_unpredicted * 1e3);
  EXPECT_LT(worst, 0.35e-3);
  EXPECT_GT(worst_unpredicted, 10 * worst);
  // No lead, a bad one: the orientation as carried.
  EXPECT_TRUE(g->predicted(0).isApprox(g->R()));
  EXPECT_TRUE(g->predicted(std::nan("")).isApprox(g->R()));
}

TEST(GyroOrientation, GravityPullsTheTiltDriftBack) {
  // A bias of 1 deg/s about the projector's x axis left in: gravity pulls back the tilt
  // it turns.
  const Vec3 pitch_bias(degToRad(1.0), 0, 0);
  const Turn turn = firstTurn(false, pitch_bias);
  double tilt[2] = {0, 0}, total[2] = {0, 0};
  for (int i = 0; i < 2; ++i) {
    const double gain = i == 0 ? 0.0 : 2.0;
    auto g = GyroOrientation::create({gain, 0.5});
    ASSERT_TRUE(g);
    g->start(turn.start, turn.rates.front().second, turn.rates.front().first);
    for (std::size_t k = 1; k < turn.rates.size(); ++k) {
      g->update(turn.rates[k].first, turn.downs[k], turn.rates[k].second);
    }
    tilt[i] = std::acos(std::min(1.0, (g->R() * Vec3(0, 0, -1)).dot(turn.end * Vec3(0, 0, -1))));
    total[i] = angleBetween(g->R(), turn.end);
    std::printf("gain %.1f: gravity off by %.3f mrad, orientation by %.3f mrad\n", gain,
                tilt[i] * 1e3, total[i] * 1e3);
  }
  // Without the pull: about the bias times the turn's second (17 mrad); a gain of 2/s
  // holds it to bias / gain * (1 - exp(-2)) = 7.5 mrad.
  EXPECT_GT(tilt[0], 15e-3);
  EXPECT_LT(tilt[1], 8e-3);
}

TEST(GyroOrientation, BiasFromTheStillHoldAndBadInput) {
  auto scene = sim::resolveScene("handheld_tour");
  ASSERT_TRUE(scene);
  const sim::TiltSensorSpec& spec = scene->tiltSensors().front();
  GyroBias bias;
  EXPECT_FALSE(bias.known());
  for (int k = 0; k < 900; ++k) {  // the first hold: 9 s still
    auto w = sim::sampleGyro(*scene, spec.name, k / spec.rate_hz);
    ASSERT_TRUE(w);
    bias.addStill(spec.sensor_from_projector.transpose() * w->value);
  }
  bias.addStill(Vec3(1, 0, 0));  // a turn starting: left out
  ASSERT_TRUE(bias.known());     // the hold's mean, before the hold ends
  const Vec3 during = bias.value();
  bias.endHold();
  ASSERT_TRUE(bias.known());
  EXPECT_EQ(bias.value(), during);
  const Vec3 truth =
      spec.sensor_from_projector.transpose() * sim::sampleGyro(*scene, spec.name, 3.0)->bias;
  // The mean of 900 readings: sigma = density * sqrt(rate / 2) / sqrt(900), plus the walk.
  EXPECT_LT((bias.value() - truth).norm(), degToRad(0.01)) << bias.value().transpose();

  EXPECT_FALSE(GyroOrientation::create({-1, 0.5}));
  EXPECT_FALSE(GyroOrientation::create({0.5, 0}));
  auto g = GyroOrientation::create();
  ASSERT_TRUE(g);
  g->start(Mat3::Identity(), 1000);
  g->update(Vec3(NAN, 0, 0), std::nullopt, 2000);
  g->update(Vec3(1, 0, 0), std::nullopt, 500);  // older: nothing
  EXPECT_EQ(g->R(), Mat3::Identity());
  EXPECT_TRUE(g->running());
  g->update(Vec3(1, 0, 0), std::nullopt, 1000 + 600'000'000);  // a gap of 0.6 s: unknown turn
  EXPECT_EQ(g->R(), Mat3::Identity());
  EXPECT_FALSE(g->running());
}

}  // namespace
}  // namespace procam::keystone
