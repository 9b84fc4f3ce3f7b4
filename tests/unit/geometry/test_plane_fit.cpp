// Tests for pipelines/geometry/plane_fit: least squares and RANSAC against planes
// the points were sampled from.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "geometry/plane_fit.hpp"

namespace procam::geom {
namespace {

// Points on n.x + d = 0 with in-plane extent `spread` around `center`, plus noise.
Points3 planePoints(std::mt19937_64& rng, const Vec3& n, const Vec3& center, double spread,
                    int count, double sigma) {
  const Vec3 u = n.unitOrthogonal();
  const Vec3 v = n.cross(u);
  std::uniform_real_distribution<double> w(-spread, spread);
  std::normal_distribution<double> g(0, sigma > 0 ? sigma : 1);
  Points3 pts;
  for (int i = 0; i < count; ++i) {
    pts.push_back(center + w(rng) * u + w(rng) * v + (sigma > 0 ? g(rng) : 0.0) * n);
  }
  return pts;
}

double normalAngle(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));  // acos is blind below 1e-8
}

TEST(PlaneFit, ExactPointsGiveThePlane) {
  std::mt19937_64 rng(1);
  const Vec3 n = Vec3(1, -2, 0.5).normalized();
  const Vec3 c(3, 1, -2);
  const auto fit = fitPlane(planePoints(rng, n, c, 2, 40, 0));
  ASSERT_TRUE(fit);
  EXPECT_LT(normalAngle(fit->plane.n, n), 1e-14);
  EXPECT_NEAR(fit->plane.n.norm(), 1, 1e-15);
  EXPECT_NEAR(std::abs(fit->plane.signedDistance(c)), 0, 1e-14);
  EXPECT_LT(fit->rms, 1e-14);
  EXPECT_EQ(fit->inliers.size(), 40u);
  // Orientation convention: largest-magnitude component of n positive.
  EXPECT_GT(fit->plane.n.y(), 0);
  EXPECT_TRUE(fit->plane.n.isApprox(-n, 1e-14));
}

TEST(PlaneFit, NoisyPointsGiveExpectedResidual) {
  // rms^2 has n - 3 degrees of freedom: E = sigma^2 (n - 3) / n; 2000 points
  // scatter the rms by ~1.6%, 6% is a 4-sigma band.
  std::mt19937_64 rng(2);
  const Vec3 n = Vec3(0.2, 0.1, 1).normalized();
  const double sigma = 1e-3;
  const int count = 2000;
  const auto fit = fitPlane(planePoints(rng, n, Vec3(0, 0, 2), 1, count, sigma));
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->rms, sigma * std::sqrt((count - 3.0) / count), 0.06 * sigma);
  // Normal error ~ sigma / (sqrt(n) * extent rms 0.58): ~4e-5 rad.
  EXPECT_LT(normalAngle(fit->plane.n, n), 2e-4);
}

TEST(PlaneFit, FarOffsetSmallPatch) {
  // A 10-unit patch 1e4 from the origin: centring first keeps the normal exact to
  // rounding of the coordinates (~2e-12 / 10).
  std::mt19937_64 rng(3);
  const Vec3 n = Vec3(-0.3, 0.9, 0.1).normalized();
  const Vec3 c(1e4, -1e4, 1e4);
  const auto fit = fitPlane(planePoints(rng, n, c, 5, 100, 0));
  ASSERT_TRUE(fit);
  EXPECT_LT(normalAngle(fit->plane.n, n), 1e-11);
  EXPECT_LT(std::abs(fit->plane.signedDistance(c)), 1e-8);
}

TEST(PlaneFit, DegenerateInputsAreTypedErrors) {
  const Points3 line = {{0, 0, 0}, {1, 2, 3}, {2, 4, 6}, {-1, -2, -3}};
  auto fit = fitPlane(line);
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
  const Points3 same(6, Vec3(1, 1, 1));
  fit = fitPlane(same);
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
  fit = fitPlane(std::span(line).first(2));
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kTooFewPoints);
  Points3 nan = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, INFINITY}};
  fit = fitPlane(nan);
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kInvalidInput);
  // Vertices of a regular octahedron: isotropic, every plane through the centre fits
  // equally badly, so there is no unique answer.
  const Points3 octa = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  fit = fitPlane(octa);
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
}

TEST(PlaneRansac, FindsThePlaneAmongOutliers) {
  std::mt19937_64 rng(4);
  const Vec3 n = Vec3(0.1, -0.3, 1).normalized();
  const Vec3 c(0.5, 0.5, 1);
  const double sigma = 1e-4;
  Points3 pts = planePoints(rng, n, c, 1, 700, sigma);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 300; ++i) pts.push_back(c + Vec3(u(rng), u(rng), u(rng)));
  RansacOptions opt;
  opt.threshold = 5 * sigma;
  opt.seed = 42;
  const auto fit = fitPlaneRansac(pts, opt);
  ASSERT_TRUE(fit) << fit.error().message;
  // All 700 true inliers are within 5 sigma of the plane (P(miss) ~ 6e-7 each);
  // outliers fall into the 1e-3-thick band with probability ~ 1e-3 / 2 (< 1 expected).
  const auto true_in = std::count_if(fit->inliers.begin(), fit->inliers.end(),
                                     [](std::uint32_t i) { return i < 700; });
  EXPECT_EQ(true_in, 700);
  EXPECT_LE(fit->inliers.size(), 704u);
  EXPECT_LT(normalAngle(fit->plane.n, n), 1e-4);
  EXPECT_LT(std::abs(fit->plane.signedDistance(c)), 5e-5);
  EXPECT_NEAR(fit->rms, sigma, 0.2 * sigma);
  // Deterministic for a seed.
  const auto again = fitPlaneRansac(pts, opt);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->inliers, fit->inliers);
  EXPECT_EQ(again->plane.n, fit->plane.n);
}

TEST(PlaneRansac, TwoPlanesPicksTheLargerOne) {
  std::mt19937_64 rng(5);
  Points3 pts = planePoints(rng, Vec3::UnitZ(), Vec3::Zero(), 1, 400, 0);
  const Points3 wall = planePoints(rng, Vec3::UnitX(), Vec3(1.5, 0, 0), 1, 250, 0);
  pts.insert(pts.end(), wall.begin(), wall.end());
  const auto fit = fitPlaneRansac(pts, {});
  ASSERT_TRUE(fit);
  EXPECT_LT(normalAngle(fit->plane.n, Vec3::UnitZ()), 1e-12);
  EXPECT_EQ(fit->inliers.size(), 400u);
}

TEST(PlaneRansac, DegenerateAndInvalidInputs) {
  Points3 line;
  for (int i = 0; i < 50; ++i) line.push_back(Vec3(i, 2 * i, -i));
  auto fit = fitPlaneRansac(line, {});
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
  const Points3 tri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  RansacOptions bad;
  bad.threshold = 0;
  fit = fitPlaneRansac(tri, bad);
  ASSERT_FALSE(fit);
  EXPECT_EQ(fit.error().code, ErrorCode::kInvalidInput);
  bad = {};
  bad.confidence = 1;
  EXPECT_FALSE(fitPlaneRansac(tri, bad));
  RansacOptions one;
  one.iterations = 1;
  fit = fitPlaneRansac(tri, one);  // any sample of 3 points is the plane
  ASSERT_TRUE(fit);
  EXPECT_LT(normalAngle(fit->plane.n, Vec3::UnitZ()), 1e-15);
}

}  // namespace
}  // namespace procam::geom
