// Tests for pipelines/geometry/homography
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/homography.hpp"
#include "unit/geometry/synthetic_views.hpp"

namespace procam::geom {
namespace {

constexpr double kW = 1920, kH = 1080;
// Exact data: transfer error over the image below 1e-9 of its width (double precision
// times the condition numbers of these well-spread configurations, ~1e2).
constexpr double kExactPx = 1e-9 * kW;

Mat3 truthH() {
  const auto a = testing::makeCamera({0.3, -5, 1.5}, {0, 0, 0});
  const auto b = testing::makeCamera({2.2, -4, 2.5}, {0.2, 0.1, 0});
  return testing::planeHomography(a.projectionMatrix(), b.projectionMatrix());
}

struct Pairs {
  Points2 src, dst;
};

Pairs exactPairs(const Mat3& H, int n, std::mt19937_64& rng, Vec2 offset = Vec2::Zero()) {
  Pairs p;
  for (int i = 0; i < n; ++i) {
    const Vec2 s = testing::uniformPixel(rng, kW, kH);
    p.src.push_back(s + offset);
    p.dst.push_back((H * s.homogeneous()).hnormalized() + offset);
  }
  return p;
}

TEST(Homography, ApplyAndPointsAtInfinity) {
  Mat3 H;
  H << 2, 0, 1, 0, 3, -1, 0, 0, 1;
  auto p = applyHomography(H, {1, 2});
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(*p, Vec2(3, 5));
  Mat3 G;
  G << 1, 0, 0, 0, 1, 0, 1, 0, 0;  // w = x
  EXPECT_FALSE(applyHomography(G, {0, 5}).has_value());
  EXPECT_FALSE(applyHomography(H, {std::nan(""), 1}).has_value());
}

TEST(Homography, FourPointSolveIsExact) {
  const Mat3 Ht = truthH();
  const std::array<Vec2, 4> src{Vec2(100, 80), Vec2(1800, 120), Vec2(1700, 1000), Vec2(200, 950)};
  std::array<Vec2, 4> dst;
  for (int i = 0; i < 4; ++i) dst[i] = (Ht * src[i].homogeneous()).hnormalized();
  auto H = homographyFrom4(src, dst);
  ASSERT_TRUE(H.has_value()) << H.error().message;
  EXPECT_LT(testing::maxTransferDifference(*H, Ht, kW, kH), kExactPx);
  EXPECT_NEAR(H->norm(), 1.0, 1e-12);
  EXPECT_GE((*H)(2, 2), 0);
  // The DLT with four points interpolates them too.
  auto dlt = fitHomographyDlt(src, dst);
  ASSERT_TRUE(dlt.has_value());
  EXPECT_LT(testing::maxTransferDifference(dlt->H, Ht, kW, kH), kExactPx);
}

TEST(Homography, FourPointSolveRejectsCollinearAndDuplicates) {
  const std::array<Vec2, 4> square{Vec2(0, 0), Vec2(100, 0), Vec2(100, 100), Vec2(0, 100)};
  const std::array<Vec2, 4> collinear{Vec2(0, 0), Vec2(100, 0), Vec2(50, 0), Vec2(0, 100)};
  const std::array<Vec2, 4> duplicate{Vec2(0, 0), Vec2(100, 0), Vec2(100, 0), Vec2(0, 100)};
  for (const auto& bad : {collinear, duplicate}) {
    auto a = homographyFrom4(bad, square);
    auto b = homographyFrom4(square, bad);
    auto c = fitHomographyDlt(bad, square);
    ASSERT_FALSE(a.has_value() || b.has_value() || c.has_value());
    EXPECT_EQ(a.error().code, ErrorCode::kDegenerate);
    EXPECT_EQ(b.error().code, ErrorCode::kDegenerate);
    EXPECT_EQ(c.error().code, ErrorCode::kDegenerate);
  }
  std::array<Vec2, 4> nan = square;
  nan[2].x() = std::nan("");
  auto r = homographyFrom4(nan, square);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

TEST(Homography, DltExactForManyPointsAndLargeOffsets) {
  const Mat3 Ht = truthH();
  std::mt19937_64 rng(7);
  for (int n : {5, 20, 300}) {
    const Pairs p = exactPairs(Ht, n, rng);
    auto fit = fitHomographyDlt(p.src, p.dst);
    ASSERT_TRUE(fit.has_value()) << fit.error().message;
    EXPECT_LT(testing::maxTransferDifference(fit->H, Ht, kW, kH), kExactPx) << n;
    EXPECT_LT(fit->rms, kExactPx);
    EXPECT_EQ(fit->iterations, 0);
    EXPECT_GT(fit->condition, 1.0);
    EXPECT_LT(fit->condition, 1e3);
  }
  // Offsetting both images by 1e4 px changes nothing after normalisation: same
  // condition number and the same (translated) homography.
  std::mt19937_64 rng_a(3), rng_b(3);
  const Pairs near = exactPairs(Ht, 30, rng_a);
  const Pairs far = exactPairs(Ht, 30, rng_b, Vec2(1e4, -1e4));
  auto f_near = fitHomography(near.src, near.dst);
  auto f_far = fitHomography(far.src, far.dst);
  ASSERT_TRUE(f_near && f_far);
  EXPECT_NEAR(f_far->condition, f_near->condition, 1e-6 * f_near->condition);
  Mat3 T = Mat3::Identity();
  T(0, 2) = 1e4;
  T(1, 2) = -1e4;
  const Mat3 Ht_far = T * Ht * T.inverse();
  EXPECT_LT(testing::maxTransferDifference(f_far->H * T, Ht_far * T, kW, kH), kExactPx);
}

TEST(Homography, RejectsBadInput) {
  const Points2 a{{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.3}};
  const Points2 b{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  auto size = fitHomography(a, b);
  ASSERT_FALSE(size.has_value());
  EXPECT_EQ(size.error().code, ErrorCode::kInvalidInput);
  const Points2 three{{0, 0}, {1, 0}, {1, 1}};
  auto few = fitHomography(three, three);
  ASSERT_FALSE(few.has_value());
  EXPECT_EQ(few.error().code, ErrorCode::kTooFewPoints);
  Points2 line, other;
  for (int i = 0; i < 10; ++i) {
    line.push_back({10.0 * i, 3.0 * i + 1});
    other.push_back({7.0 * i, 11.0 * (i % 3)});
  }
  auto col = fitHomography(line, other);
  ASSERT_FALSE(col.has_value());
  EXPECT_EQ(col.error().code, ErrorCode::kDegenerate);
  Points2 inf = a;
  inf[1].y() = INFINITY;
  auto nonfinite = fitHomography(inf, a);
  ASSERT_FALSE(nonfinite.has_value());
  EXPECT_EQ(nonfinite.error().code, ErrorCode::kInvalidInput);
}

TEST(Homography, ConditionLimitGivesIllConditioned) {
  // Ten points on a line plus two just off it: determined, but barely.
  const Mat3 Ht = truthH();
  Points2 src, dst;
  for (int i = 0; i < 10; ++i) src.push_back({100.0 + 150 * i, 200.0 + 60 * i});
  src.push_back({700, 440.01});
  src.push_back({1300, 679.99});
  for (const Vec2& s : src) dst.push_back((Ht * s.homogeneous()).hnormalized());
  auto loose = fitHomography(src, dst, {.max_condition = 1e12});
  ASSERT_TRUE(loose.has_value());
  EXPECT_GT(loose->condition, 1e4);
  auto strict = fitHomography(src, dst, {.max_condition = 1e4});
  ASSERT_FALSE(strict.has_value());
  EXPECT_EQ(strict.error().code, ErrorCode::kIllConditioned);
}

// Noise in dst only, σ per coordinate. For the ML estimate Hartley & Zisserman
// (Result 5.2, d = 8 parameters, N = 2n measurements) give
//   E[rms²] = σ² (1 - 4/n)   (residual)      E[est²] = σ² 4/n   (estimate vs truth),
// est = RMS over the points of |Ĥx - H x|. Each trial's n·rms²/σ² ~ χ²(2n - 8)/2 to
// first order, so the mean over T trials has relative standard error sqrt(2/((2n-8)T)).
TEST(Homography, NoisyFitReachesMaximumLikelihoodBounds) {
  const Mat3 Ht = truthH();
  const double sigma = 0.5;
  const int n = 40, trials = 300;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0, sigma);
  double sum_res = 0, sum_est = 0, sum_res_dlt = 0;
  for (int t = 0; t < trials; ++t) {
    Pairs p = exactPairs(Ht, n, rng);
    Points2 truth = p.dst;
    for (Vec2& d : p.dst) d += Vec2(noise(rng), noise(rng));
    auto fit = fitHomography(p.src, p.dst);
    auto dlt = fitHomographyDlt(p.src, p.dst);
    ASSERT_TRUE(fit && dlt);
    EXPECT_GT(fit->iterations, 0);
    EXPECT_LE(fit->rms, dlt->rms);
    sum_res += fit->rms * fit->rms;
    sum_res_dlt += dlt->rms * dlt->rms;
    double est = 0;
    for (int i = 0; i < n; ++i) {
      est += (applyHomography(fit->H, p.src[i]).value() - truth[i]).squaredNorm();
    }
    sum_est += est / n;
  }
  const double res_bound = sigma * sigma * 2 * (1 - 4.0 / n);  // 2 coordinates per point
  const double est_bound = sigma * sigma * 2 * (4.0 / n);
  const double se_res = std::sqrt(2.0 / ((2 * n - 8) * trials));
  const double se_est = std::sqrt(2.0 / (8.0 * trials));
  EXPECT_NEAR(sum_res / trials / res_bound, 1.0, 5 * se_res);
  EXPECT_NEAR(sum_est / trials / est_bound, 1.0, 5 * se_est);
  EXPECT_GE(sum_res_dlt, sum_res);
}

TEST(Homography, RefineConvergesFromPerturbedStart) {
  const Mat3 Ht = truthH();
  std::mt19937_64 rng(5);
  const Pairs p = exactPairs(Ht, 25, rng);
  Mat3 H0 = Ht / Ht.norm();
  H0(0, 2) += 0.02 * std::abs(H0(0, 2)) + 1e-4;
  H0(2, 0) *= 1.05;
  auto fit = refineHomography(H0, p.src, p.dst);
  ASSERT_TRUE(fit.has_value()) << fit.error().message;
  EXPECT_GT(fit->iterations, 0);
  EXPECT_LT(testing::maxTransferDifference(fit->H, Ht, kW, kH), 1e-6);
  EXPECT_LT(fit->rms, 1e-7);
  auto zero = refineHomography(Mat3::Zero(), p.src, p.dst);
  ASSERT_FALSE(zero.has_value());
  EXPECT_EQ(zero.error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::geom
