#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "keystone/accel_calibration.hpp"

namespace procam::keystone {
namespace {

const Vec3 kOffset(0.05, -0.03, 0.02);
const Vec3 kScale(1.02, 0.98, 1.01);

Vec3 raw(const Vec3& f) {
  return kScale.cwiseProduct(f) + kOffset;
}

std::vector<Vec3> sixPoses(double misalignment_rad) {
  std::vector<Vec3> out;
  const Eigen::AngleAxisd tilt(misalignment_rad, Vec3(1, 2, 3).normalized());
  for (int a = 0; a < 3; ++a)
    for (double s : {1.0, -1.0}) out.push_back(raw(tilt * (s * Vec3::Unit(a))));
  return out;
}

TEST(AccelCalibration, ExactFromSixAlignedPoses) {
  auto fit = calibrateSixPosition(sixPoses(0));
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_NEAR((fit->calibration.offset - kOffset).norm(), 0, 1e-12);
  EXPECT_NEAR((fit->calibration.scale - kScale).norm(), 0, 1e-12);
  EXPECT_NEAR(fit->calibration.apply(raw(Vec3(0.6, 0, 0.8))).norm(), 1, 1e-12);
}

TEST(AccelCalibration, ExactFromImperfectlyPlacedPoses) {
  // Each pose 8° off its axis: the simple max/min formula would be biased, the fit
  // on |f| = 1 is not. Six exact readings with six unknowns: an exact solve.
  std::vector<Vec3> poses;
  for (int a = 0; a < 3; ++a)
    for (double s : {1.0, -1.0}) {
      const Eigen::AngleAxisd tilt(8 * M_PI / 180, Vec3(1 + a, 2 * s, 3).normalized());
      poses.push_back(raw(tilt * (s * Vec3::Unit(a))));
    }
  auto fit = calibrateSixPosition(poses);
  ASSERT_TRUE(fit);
  EXPECT_NEAR((fit->calibration.offset - kOffset).norm(), 0, 1e-9);
  EXPECT_NEAR((fit->calibration.scale - kScale).norm(), 0, 1e-9);
}

TEST(AccelCalibration, LeastSquaresWithNoisyRepeats) {
  // 4 noisy repeats of each pose (sigma 1 mg): the offset error is ~ sigma / sqrt(4 * 2)
  // per axis; allow 4 sigma of that.
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0, 1e-3);
  std::vector<Vec3> poses;
  for (int rep = 0; rep < 4; ++rep)
    for (const Vec3& r : sixPoses(0.05))
      poses.push_back(r + Vec3(noise(rng), noise(rng), noise(rng)));
  auto fit = calibrateSixPosition(poses);
  ASSERT_TRUE(fit);
  EXPECT_LT((fit->calibration.offset - kOffset).cwiseAbs().maxCoeff(), 4 * 1e-3 / std::sqrt(8.0));
  EXPECT_NEAR(fit->rms, 1e-3, 0.6e-3);
}

TEST(AccelCalibration, TypedErrors) {
  std::vector<Vec3> poses = sixPoses(0);
  poses[5] = poses[4];  // no reading with z pointing down
  EXPECT_EQ(calibrateSixPosition(poses).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(calibrateSixPosition(std::span(poses).first(5)).error().code, ErrorCode::kTooFewPoints);
  poses = sixPoses(0);
  poses[2].y() = NAN;
  EXPECT_EQ(calibrateSixPosition(poses).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::keystone
