// Tests for pipelines/geometry/triangulate: closest point of two rays and linear
// triangulation against points built by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/triangulate.hpp"

namespace procam::geom {
namespace {

// P = K [R | t] built here so these tests do not rely on camera_model.cpp.
Mat34 makeP(double f, double cx, double cy, const Mat3& R, const Vec3& center) {
  Mat3 K;
  K << f, 0, cx, 0, f, cy, 0, 0, 1;
  Mat34 Rt;
  Rt << R, -R * center;
  return K * Rt;
}

Vec2 project(const Mat34& P, const Vec3& X) {
  const Vec3 x = P * X.homogeneous();
  return x.hnormalized();
}

// Camera at `center` looking at `target` (+z forward, y down).
Mat3 lookAt(const Vec3& center, const Vec3& target) {
  const Vec3 z = (target - center).normalized();
  const Vec3 x = Vec3(0, -1, 0).cross(z).normalized();
  const Vec3 y = z.cross(x);
  Mat3 R;
  R << x.transpose(), y.transpose(), z.transpose();
  return R;
}

TEST(TriangulateRays, IntersectingRaysMeetExactly) {
  const Vec3 X(1, 2, 3);
  const Ray a{Vec3(0, 0, 0), X.normalized()};
  const Ray b{Vec3(4, 0, 0), (X - Vec3(4, 0, 0)).normalized()};
  const auto p = triangulateRays(a, b);
  ASSERT_TRUE(p);
  EXPECT_LT((p->point - X).norm(), 1e-14);
  EXPECT_LT(p->gap, 1e-14);
  EXPECT_NEAR(p->t1, X.norm(), 1e-14);
  EXPECT_NEAR(p->t2, (X - Vec3(4, 0, 0)).norm(), 1e-14);
}

TEST(TriangulateRays, SkewRaysGiveMidpointAndGap) {
  // x axis at z = 0 and a line along -y at z = 2 through (0, 5, 2).
  const Ray a{Vec3(-3, 0, 0), Vec3(1, 0, 0)};
  const Ray b{Vec3(0, 5, 2), Vec3(0, -1, 0)};
  const auto p = triangulateRays(a, b);
  ASSERT_TRUE(p);
  EXPECT_LT((p->point - Vec3(0, 0, 1)).norm(), 1e-15);
  EXPECT_NEAR(p->gap, 2, 1e-15);
  EXPECT_NEAR(p->t1, 3, 1e-15);
  EXPECT_NEAR(p->t2, 5, 1e-15);
  // Pointing away: the closest points are behind both origins (negative t).
  const auto back = triangulateRays(Ray{a.origin, -a.dir}, Ray{b.origin, -b.dir});
  ASSERT_TRUE(back);
  EXPECT_NEAR(back->t1, -3, 1e-15);
  EXPECT_NEAR(back->t2, -5, 1e-15);
}

TEST(TriangulateRays, ParallelAndInvalidRaysAreTypedErrors) {
  const Ray a{Vec3(0, 0, 0), Vec3(0, 0, 1)};
  auto p = triangulateRays(a, Ray{Vec3(1, 0, 0), Vec3(0, 0, 1)});
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, ErrorCode::kDegenerate);
  p = triangulateRays(a, Ray{Vec3(1, 0, 0), Vec3(1e-10, 0, 1).normalized()});
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, ErrorCode::kDegenerate);
  p = triangulateRays(a, Ray{Vec3(1, 0, 0), Vec3(-1, 0, 0).cross(Vec3::Zero())});
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, ErrorCode::kInvalidInput);
  p = triangulateRays(a, Ray{Vec3(NAN, 0, 0), Vec3(1, 0, 0)});
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, ErrorCode::kInvalidInput);
}

TEST(TriangulateLinear, ExactViewsRecoverThePoint) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 X(u(rng), u(rng), 3 + u(rng));
    std::vector<Mat34> P;
    std::vector<Vec2> px;
    const int views = 2 + trial % 4;
    for (int v = 0; v < views; ++v) {
      const Vec3 c(2 * u(rng), 0.5 * u(rng), u(rng) - 1);
      P.push_back(makeP(1200, 960, 540, lookAt(c, Vec3(0, 0, 3)), c));
      px.push_back(project(P.back(), X));
    }
    const auto r = triangulateLinear(P, px);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_LT((*r - X).norm(), 1e-10);
  }
}

TEST(TriangulateLinear, FarOffsetWorldAnd4kPixels) {
  // Scene 1e4 units from the origin and raw 4K pixel coordinates: the world and
  // row normalisation keep the solve exact to rounding.
  const Vec3 offset(1e4, -1e4, 1e4);
  const Vec3 X = offset + Vec3(0.3, -0.2, 5);
  const Vec3 c1 = offset + Vec3(-0.5, 0, 0), c2 = offset + Vec3(0.5, 0.1, 0);
  const Mat34 P1 = makeP(3000, 1919.5, 1079.5, lookAt(c1, offset + Vec3(0, 0, 5)), c1);
  const Mat34 P2 = makeP(3000, 1919.5, 1079.5, lookAt(c2, offset + Vec3(0, 0, 5)), c2);
  const std::vector<Mat34> P = {P1, P2};
  const std::vector<Vec2> px = {project(P1, X), project(P2, X)};
  const auto r = triangulateLinear(P, px);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_LT((*r - X).norm(), 1e-8);
}

TEST(TriangulateLinear, NoisyPixelsStayWithinStereoErrorBound) {
  // Rectified stereo pair, independent pixel noise sigma on every coordinate. To
  // first order the disparity error is sigma*sqrt(2), so sigma_Z = sqrt(2) sigma Z^2 / (f B),
  // and the lateral error of the two-view average is sigma Z / (f sqrt(2)) per axis.
  const double f = 1000, B = 0.5, Z = 3, sigma = 0.5;
  const double sigma_z = std::sqrt(2.0) * sigma * Z * Z / (f * B);
  const double sigma_xy = sigma * Z / (f * std::sqrt(2.0));
  const double expected = std::sqrt(sigma_z * sigma_z + 2 * sigma_xy * sigma_xy);
  const Vec3 c1(-B / 2, 0, 0), c2(B / 2, 0, 0);
  const std::vector<Mat34> P = {makeP(f, 640, 480, Mat3::Identity(), c1),
                                makeP(f, 640, 480, Mat3::Identity(), c2)};
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0, sigma);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  double ss = 0;
  const int trials = 400;
  for (int i = 0; i < trials; ++i) {
    const Vec3 X(u(rng), u(rng), Z);
    std::vector<Vec2> px = {project(P[0], X) + Vec2(g(rng), g(rng)),
                            project(P[1], X) + Vec2(g(rng), g(rng))};
    const auto r = triangulateLinear(P, px);
    ASSERT_TRUE(r);
    ss += (*r - X).squaredNorm();
  }
  // 400 samples scatter the rms by ~3.5%; the first-order model (and the coupling of
  // depth error into X, Y by |X|/Z <= 0.17) adds a few percent: 15% band.
  EXPECT_NEAR(std::sqrt(ss / trials), expected, 0.15 * expected);
}

TEST(TriangulateLinear, DegenerateConfigurationsAreTypedErrors) {
  const Vec3 c1(0, 0, 0), c2(1, 0, 0);
  const Mat34 P1 = makeP(800, 320, 240, Mat3::Identity(), c1);
  const Mat34 P2 = makeP(800, 320, 240, Mat3::Identity(), c2);
  const Vec3 X(0.2, 0.1, 4);
  // Same camera twice: a single ray, no depth.
  std::vector<Mat34> P = {P1, P1};
  std::vector<Vec2> px = {project(P1, X), project(P1, X)};
  auto r = triangulateLinear(P, px);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
  // Same pixel in two parallel cameras: parallel rays, the point is at infinity.
  P = {P1, P2};
  px = {Vec2(400, 300), Vec2(400, 300)};
  r = triangulateLinear(P, px);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
  px = {Vec2(400, 300)};
  r = triangulateLinear(std::span(P).first(1), px);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooFewPoints);
  r = triangulateLinear(P, px);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  px = {Vec2(400, NAN), Vec2(400, 300)};
  r = triangulateLinear(P, px);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::geom
