// Tests for pipelines/geometry/projection_matrix
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/projection_matrix.hpp"
#include "unit/geometry/synthetic_views.hpp"

namespace procam::geom {
namespace {

// Points inside a box of the given half extents around `center`.
Points3 boxPoints(int n, const Vec3& center, const Vec3& half, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Points3 pts;
  for (int i = 0; i < n; ++i)
    pts.push_back(center + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(half));
  return pts;
}

Points2 projectAll(const CameraModel& cam, const Points3& pts) {
  Points2 px;
  for (const Vec3& X : pts) px.push_back(cam.project(X).value());
  return px;
}

// Distance between projection matrices up to scale and sign.
double matrixDistance(const Mat34& A, const Mat34& B) {
  const Mat34 a = A / A.norm(), b = B / B.norm();
  return std::min((a - b).norm(), (a + b).norm());
}

void expectDecompositionMatches(const KRt& got, const CameraModel& cam, double tol) {
  EXPECT_NEAR(got.K.fx, cam.K.fx, tol * cam.K.fx);
  EXPECT_NEAR(got.K.fy, cam.K.fy, tol * cam.K.fy);
  EXPECT_NEAR(got.K.cx, cam.K.cx, tol * cam.K.fx);
  EXPECT_NEAR(got.K.cy, cam.K.cy, tol * cam.K.fy);
  EXPECT_NEAR(got.K.skew, cam.K.skew, tol * cam.K.fx);
  EXPECT_LT((got.pose.R - cam.pose.R).norm(), tol);
  EXPECT_LT((got.pose.t - cam.pose.t).norm(), tol * (1 + cam.pose.t.norm()));
  EXPECT_NEAR(got.pose.R.determinant(), 1.0, 1e-12);
}

TEST(ProjectionMatrix, ExactDataRecoversCamera) {
  const CameraModel cam = testing::makeCamera({1.5, -6, 2.0}, {0, 0, 1}, 1300, 3840, 2160);
  std::mt19937_64 rng(2);
  for (int n : {6, 12, 200}) {
    const Points3 X = boxPoints(n, {0, 0, 1}, {1.5, 1.0, 0.8}, rng);
    auto fit = fitProjectionMatrix(X, projectAll(cam, X));
    ASSERT_TRUE(fit.has_value()) << fit.error().message;
    EXPECT_LT(matrixDistance(fit->P, cam.projectionMatrix()), 1e-10) << n;
    EXPECT_NEAR(fit->P.norm(), 1.0, 1e-12);
    EXPECT_LT(fit->rms, 1e-8);
    for (const Vec3& x : X) EXPECT_GT((fit->P * x.homogeneous()).z(), 0);  // in front
    auto krt = decomposeProjectionMatrix(fit->P);
    ASSERT_TRUE(krt.has_value()) << krt.error().message;
    expectDecompositionMatches(*krt, cam, 1e-9);
  }
}

TEST(ProjectionMatrix, DecomposeIsIndependentOfScaleAndSign) {
  const CameraModel cam = testing::makeCamera({-3, -2, 1.2}, {0.5, 0.5, 0.7}, 950);
  for (double s : {1.0, -1.0, 1e-6, -3e5}) {
    auto krt = decomposeProjectionMatrix(s * cam.projectionMatrix());
    ASSERT_TRUE(krt.has_value());
    expectDecompositionMatches(*krt, cam, 1e-12);
  }
  // World coordinates far from the origin (t ~ 1e4) keep the decomposition exact.
  CameraModel far = cam;
  far.pose.t += far.pose.R * Vec3(-1e4, 2e4, 500);
  auto krt = decomposeProjectionMatrix(far.projectionMatrix());
  ASSERT_TRUE(krt.has_value());
  expectDecompositionMatches(*krt, far, 1e-9);
}

TEST(ProjectionMatrix, DecomposeRejectsCameraAtInfinity) {
  Mat34 affine = Mat34::Zero();
  affine.row(0) << 800, 0, 0, 320;
  affine.row(1) << 0, 800, 0, 240;
  affine(2, 3) = 1;
  auto r = decomposeProjectionMatrix(affine);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
  Mat34 nan = affine;
  nan(1, 1) = std::nan("");
  EXPECT_EQ(decomposeProjectionMatrix(nan).error().code, ErrorCode::kInvalidInput);
}

TEST(ProjectionMatrix, CoplanarPointsAreATypedErrorWithAdvice) {
  const CameraModel cam = testing::makeCamera({1, -5, 1.5}, {0, 0, 1});
  std::mt19937_64 rng(4);
  // [Raskar02] §4.1.1: one wall alone cannot calibrate. Exactly planar, and planar within
  // 1e-4 of the extent (below ProjectionOptions::coplanar_ratio = 1e-3).
  for (double thickness : {0.0, 2e-4}) {
    const Points3 X = boxPoints(40, {0, 0, 1}, {1.5, thickness, 1.0}, rng);
    auto fit = fitProjectionMatrix(X, projectAll(cam, X));
    ASSERT_FALSE(fit.has_value());
    EXPECT_EQ(fit.error().code, ErrorCode::kCoplanar);
    EXPECT_NE(fit.error().message.find("non-planar"), std::string::npos);
  }
  // Two walls at 90° (the corner setup of §4.1.1) calibrate.
  Points3 corner;
  for (const Vec3& p : boxPoints(20, {0, 0, 1}, {1.5, 0, 1}, rng)) corner.push_back(p);
  for (const Vec3& p : boxPoints(20, {1.5, 1.5, 1}, {0, 1.5, 1}, rng)) corner.push_back(p);
  auto fit = fitProjectionMatrix(corner, projectAll(cam, corner));
  ASSERT_TRUE(fit.has_value()) << fit.error().message;
  EXPECT_LT(matrixDistance(fit->P, cam.projectionMatrix()), 1e-10);
}

TEST(ProjectionMatrix, RejectsBadInput) {
  const CameraModel cam = testing::makeCamera({1, -5, 1.5}, {0, 0, 1});
  std::mt19937_64 rng(8);
  Points3 X = boxPoints(5, {0, 0, 1}, {1, 1, 1}, rng);
  auto few = fitProjectionMatrix(X, projectAll(cam, X));
  ASSERT_FALSE(few.has_value());
  EXPECT_EQ(few.error().code, ErrorCode::kTooFewPoints);
  // Ten pairs but only five distinct points.
  Points3 dup = X;
  dup.insert(dup.end(), X.begin(), X.end());
  auto d = fitProjectionMatrix(dup, projectAll(cam, dup));
  ASSERT_FALSE(d.has_value());
  EXPECT_EQ(d.error().code, ErrorCode::kDegenerate);
  Points3 Y = boxPoints(10, {0, 0, 1}, {1, 1, 1}, rng);
  Points2 y = projectAll(cam, Y);
  y[3].x() = std::nan("");
  EXPECT_EQ(fitProjectionMatrix(Y, y).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(fitProjectionMatrix(Y, Points2(y.begin(), y.end() - 1)).error().code,
            ErrorCode::kInvalidInput);
}

// Pixel noise σ per coordinate. At the ML estimate (HZ Result 5.2 with d = 11 and
// N = 2n): E[rms²] = 2σ² (1 - 11/(2n)) for the residual and E[est²] = 2σ² 11/(2n)
// for est = RMS of |P̂ X - P X| (estimate against the noise-free projections). Means
// over T trials have relative standard errors sqrt(2/((2n-11)T)) and sqrt(2/(11T)).
TEST(ProjectionMatrix, NoisyFitReachesMaximumLikelihoodBounds) {
  const CameraModel cam = testing::makeCamera({1.2, -5, 1.8}, {0, 0, 1}, 1200);
  const double sigma = 0.3;
  const int n = 30, trials = 200;
  std::mt19937_64 rng(21);
  std::normal_distribution<double> noise(0, sigma);
  double sum_res = 0, sum_est = 0;
  for (int t = 0; t < trials; ++t) {
    const Points3 X = boxPoints(n, {0, 0, 1}, {1.5, 1.0, 1.0}, rng);
    const Points2 truth = projectAll(cam, X);
    Points2 x = truth;
    for (Vec2& p : x) p += Vec2(noise(rng), noise(rng));
    auto fit = fitProjectionMatrix(X, x);
    ASSERT_TRUE(fit.has_value());
    sum_res += fit->rms * fit->rms;
    double est = 0;
    for (int i = 0; i < n; ++i) est += (projectWith(fit->P, X[i]).value() - truth[i]).squaredNorm();
    sum_est += est / n;
    ASSERT_TRUE(decomposeProjectionMatrix(fit->P).has_value());
  }
  const double res_bound = 2 * sigma * sigma * (1 - 11.0 / (2 * n));
  const double est_bound = 2 * sigma * sigma * (11.0 / (2 * n));
  EXPECT_NEAR(sum_res / trials / res_bound, 1.0, 5 * std::sqrt(2.0 / ((2 * n - 11) * trials)));
  EXPECT_NEAR(sum_est / trials / est_bound, 1.0, 5 * std::sqrt(2.0 / (11.0 * trials)));
}

}  // namespace
}  // namespace procam::geom
