// Tests for pipelines/geometry/rigid: transforms recovered from exact and noisy
// correspondences ([Raskar02] eq. 4.2), and typed errors for degenerate sets.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/rigid.hpp"

namespace procam::geom {
namespace {

Mat3 randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

Points3 randomCloud(std::mt19937_64& rng, int n, const Vec3& offset, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  Points3 pts;
  for (int i = 0; i < n; ++i) pts.push_back(offset + Vec3(u(rng), u(rng), u(rng)));
  return pts;
}

Points3 apply(const Points3& from, double s, const Mat3& R, const Vec3& t) {
  Points3 out;
  for (const Vec3& p : from) out.push_back(s * R * p + t);
  return out;
}

TEST(Rigid, ExactCorrespondencesGiveTheTransform) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 R = randomRotation(rng);
    const Vec3 t(3, -7, 12);
    const Points3 from = randomCloud(rng, 3 + trial, Vec3(1, 2, 3), 2);
    const auto fit = fitRigidTransform(from, apply(from, 1, R, t));
    ASSERT_TRUE(fit) << fit.error().message;
    EXPECT_LT((fit->R - R).norm(), 1e-12);
    EXPECT_LT((fit->t - t).norm(), 1e-11);
    EXPECT_EQ(fit->scale, 1.0);
    EXPECT_LT(fit->rms, 1e-12);
    EXPECT_NEAR(fit->R.determinant(), 1.0, 1e-12);
  }
}

TEST(Rigid, SimilarityRecoversScale) {
  std::mt19937_64 rng(2);
  const Mat3 R = randomRotation(rng);
  const Vec3 t(-0.5, 0.25, 4);
  const Points3 from = randomCloud(rng, 12, Vec3::Zero(), 1);
  const auto fit = fitRigidTransform(from, apply(from, 2.5, R, t), true);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->scale, 2.5, 1e-12);
  EXPECT_LT((fit->R - R).norm(), 1e-12);
  EXPECT_LT((fit->t - t).norm(), 1e-12);
  // Without scale the best rotation is still R, but residuals remain.
  const auto rigid = fitRigidTransform(from, apply(from, 2.5, R, t), false);
  ASSERT_TRUE(rigid);
  EXPECT_LT((rigid->R - R).norm(), 1e-12);
  EXPECT_GT(rigid->rms, 0.1);
}

TEST(Rigid, FarOffsetPlanarSetStaysAccurate) {
  // Coplanar points 1e4 away from the origin: exactly the case of a wall in mm.
  std::mt19937_64 rng(3);
  const Mat3 R = randomRotation(rng);
  const Vec3 t(1e4, -2e4, 5e3);
  Points3 from = randomCloud(rng, 50, Vec3(1e4, 1e4, 0), 500);
  for (Vec3& p : from) p.z() = 1e4;
  const auto fit = fitRigidTransform(from, apply(from, 1, R, t));
  ASSERT_TRUE(fit) << fit.error().message;
  // Rounding of coordinates ~3e4 is ~4e-12; rotation error ~ that over the 500 spread.
  EXPECT_LT((fit->R - R).norm(), 1e-12);
  EXPECT_LT((fit->t - t).norm(), 1e-7);
  EXPECT_LT(fit->rms, 1e-9);
}

TEST(Rigid, NoisyFitIsLeastSquaresOptimalWithExpectedResidual) {
  // Residual degrees of freedom: 3n - 6, so E[rms^2] = sigma^2 (3n - 6) / n; with
  // n = 1000 the rms scatters by ~1.3% (chi-square), 5% is a 4-sigma band.
  std::mt19937_64 rng(4);
  const int n = 1000;
  const double sigma = 0.01;
  const Mat3 R = randomRotation(rng);
  const Vec3 t(1, 2, 3);
  const Points3 from = randomCloud(rng, n, Vec3::Zero(), 1);
  Points3 to = apply(from, 1, R, t);
  std::normal_distribution<double> g(0, sigma);
  for (Vec3& p : to) p += Vec3(g(rng), g(rng), g(rng));
  const auto fit = fitRigidTransform(from, to);
  ASSERT_TRUE(fit);
  double truth_ss = 0;
  for (int i = 0; i < n; ++i) truth_ss += (R * from[i] + t - to[i]).squaredNorm();
  EXPECT_LE(fit->rms, std::sqrt(truth_ss / n));
  EXPECT_NEAR(fit->rms, sigma * std::sqrt((3.0 * n - 6) / n), 0.05 * sigma);
  // Rotation error ~ sigma / (sqrt(n) * spread ~ 0.58): well under 1e-3 rad.
  EXPECT_LT(Eigen::AngleAxisd(fit->R.transpose() * R).angle(), 1e-3);
}

TEST(Rigid, DegenerateAndInvalidInputsAreTypedErrors) {
  const Points3 line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {-3, -3, -3}};
  const Points3 other = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  auto r = fitRigidTransform(line, line);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
  r = fitRigidTransform(other, line);  // target collinear: rotation not unique either
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
  const Points3 same(5, Vec3(1, 2, 3));
  r = fitRigidTransform(same, same);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
  r = fitRigidTransform(std::span(other).first(2), std::span(other).first(2));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooFewPoints);
  r = fitRigidTransform(other, std::span(other).first(3));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  Points3 nan = other;
  nan[2].x() = NAN;
  r = fitRigidTransform(nan, other);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

TEST(Rigid, MirroredSetYieldsProperRotation) {
  // A reflection is no rigid motion: the result must still be a rotation (det +1)
  // and leave a residual, never a reflection matrix.
  const Points3 from = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {-1, 2, 0.5}};
  Points3 to = from;
  for (Vec3& p : to) p.x() = -p.x();
  const auto fit = fitRigidTransform(from, to);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->R.determinant(), 1.0, 1e-12);
  EXPECT_LT((fit->R * fit->R.transpose() - Mat3::Identity()).norm(), 1e-12);
  EXPECT_GT(fit->rms, 0.1);
}

}  // namespace
}  // namespace procam::geom
