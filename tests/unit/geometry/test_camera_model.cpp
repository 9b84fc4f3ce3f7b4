// Tests for pipelines/geometry/camera_model
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "geometry/camera_model.hpp"
#include "unit/geometry/synthetic_views.hpp"

namespace procam::geom {
namespace {

// Double-precision round trips of well-conditioned closed forms: a few hundred ulps.
constexpr double kTight = 1e-12;

Distortion typicalLens() {
  Distortion d;
  d.k1 = -0.28;
  d.k2 = 0.09;
  d.p1 = 0.0012;
  d.p2 = -0.0007;
  d.k3 = -0.015;
  return d;
}

TEST(Intrinsics, MatrixRoundTrip) {
  Intrinsics K{1200.5, 1190.25, 960.5, 540.25, 0.75};
  const Mat3 M = K.matrix();
  EXPECT_EQ(M(0, 0), 1200.5);
  EXPECT_EQ(M(0, 1), 0.75);
  EXPECT_EQ(M(0, 2), 960.5);
  EXPECT_EQ(M(1, 1), 1190.25);
  EXPECT_EQ(M(1, 2), 540.25);
  EXPECT_EQ(M(2, 2), 1.0);
  EXPECT_EQ(M(1, 0), 0.0);
  const Intrinsics back = Intrinsics::fromMatrix(-3.0 * M);  // any scale, any sign
  EXPECT_NEAR(back.fx, K.fx, kTight * K.fx);
  EXPECT_NEAR(back.fy, K.fy, kTight * K.fy);
  EXPECT_NEAR(back.cx, K.cx, kTight * K.cx);
  EXPECT_NEAR(back.cy, K.cy, kTight * K.cy);
  EXPECT_NEAR(back.skew, K.skew, kTight * K.fx);
}

TEST(Distortion, ApplyMatchesOpenCvFormula) {
  // Expected values evaluated independently from OpenCV's documented model.
  const Vec2 d = typicalLens().apply({0.41, -0.27});
  EXPECT_NEAR(d.x(), 0.38372058414585003, 1e-15);
  EXPECT_NEAR(d.y(), -0.25251593833995, 1e-15);
  // Pure radial on the x axis: x (1 + k1 x² + k2 x⁴ + k3 x⁶).
  Distortion radial;
  radial.k1 = 0.1;
  radial.k2 = 0.01;
  radial.k3 = 0.001;
  EXPECT_NEAR(radial.apply({0.5, 0}).x(), 0.5 * (1 + 0.025 + 0.000625 + 0.000015625), 1e-15);
  EXPECT_EQ(Distortion{}.apply({0.3, 0.2}), Vec2(0.3, 0.2));
}

TEST(Distortion, RemoveInvertsApplyAcrossTheField) {
  const Distortion d = typicalLens();
  // Normalised coordinates of a ~90° diagonal field of view.
  for (double x = -0.8; x <= 0.8; x += 0.05) {
    for (double y = -0.45; y <= 0.45; y += 0.05) {
      const Vec2 u(x, y);
      auto back = d.remove(d.apply(u));
      ASSERT_TRUE(back.has_value()) << x << "," << y << ": " << back.error().message;
      EXPECT_LT((*back - u).norm(), kTight) << x << "," << y;
    }
  }
}

TEST(Distortion, RemoveReportsPointsWithoutPreimage) {
  // r (1 - 0.5 r²) peaks at r = sqrt(2/3) with value 0.544: radius 0.7 has no preimage.
  Distortion d;
  d.k1 = -0.5;
  auto r = d.remove({0.7, 0.0});
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::kNoConvergence);
  auto nan = d.remove({std::nan(""), 0.0});
  ASSERT_FALSE(nan.has_value());
  EXPECT_EQ(nan.error().code, ErrorCode::kInvalidInput);
}

TEST(Distortion, FoldIsWhereTheRadialPolynomialStopsGrowing) {
  // r (1 + k1 r^2): its slope 1 + 3 k1 r^2 reaches 0 at r^2 = 1 / (3 |k1|).
  Distortion barrel;
  barrel.k1 = -0.015;
  EXPECT_TRUE(barrel.radialMonotonicUpTo(22.0));
  EXPECT_FALSE(barrel.radialMonotonicUpTo(22.5));
  // A k2 that turns the slope up again before it reaches 0: no fold anywhere.
  Distortion held = barrel;
  held.k2 = 0.004;
  EXPECT_TRUE(held.radialMonotonicUpTo(1e6));
  // A slope that dips below 0 inside the range and recovers past it: folded.
  Distortion dip;
  dip.k1 = -0.6;
  dip.k2 = 0.13;
  EXPECT_FALSE(dip.radialMonotonicUpTo(1e4));
  EXPECT_TRUE(dip.radialMonotonicUpTo(0.5));
  // The camera model images nothing past it, where apply() would fold a point off the
  // axis back into the frame.
  CameraModel cam = testing::makeCamera({0, 0, 0}, {0, 1, 0});
  cam.dist = barrel;
  const Vec3 axis = cam.pose.R.transpose().col(2), right = cam.pose.R.transpose().col(0);
  EXPECT_TRUE(cam.project(cam.pose.center() + axis + 4.6 * right).has_value());
  EXPECT_FALSE(cam.project(cam.pose.center() + axis + 4.8 * right).has_value());
  EXPECT_FALSE(cam.project(cam.pose.center() + axis + 9.0 * right).has_value());
}

TEST(Pose, InverseComposesToIdentity) {
  const Pose p = Pose::lookAt({1, -4, 2}, {0.3, 0.2, 0.5}, Vec3::UnitZ());
  const Pose q = p.inverse();
  const Vec3 x(0.7, -1.1, 3.3);
  EXPECT_LT((q.toDevice(p.toDevice(x)) - x).norm(), kTight);
  EXPECT_LT((q.R * p.R - Mat3::Identity()).norm(), kTight);
  EXPECT_LT((p.toWorld(p.toDevice(x)) - x).norm(), kTight);
}

TEST(Pose, LookAtAxesFollowConvention) {
  // Standing at the origin looking along +Y with +Z up: image x is world +X,
  // image y (down) is world -Z.
  const Pose p = Pose::lookAt(Vec3::Zero(), {0, 5, 0}, Vec3::UnitZ());
  Mat3 expected;
  expected << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  EXPECT_LT((p.R - expected).norm(), kTight);

  const Vec3 eye(2, -3, 1.5), target(-1, 1, 0.2);
  const Pose q = Pose::lookAt(eye, target, Vec3::UnitZ());
  EXPECT_LT((q.R * q.R.transpose() - Mat3::Identity()).norm(), kTight);
  EXPECT_NEAR(q.R.determinant(), 1.0, kTight);
  EXPECT_LT((q.center() - eye).norm(), kTight);
  // The target sits on the optical axis, in front.
  const Vec3 t = q.toDevice(target);
  EXPECT_NEAR(t.x(), 0, kTight);
  EXPECT_NEAR(t.y(), 0, kTight);
  EXPECT_NEAR(t.z(), (target - eye).norm(), kTight);
  // Device -y axis is the projection of up onto the image plane: up has no x component.
  EXPECT_NEAR(q.R.row(0).dot(Vec3::UnitZ()), 0, kTight);
  EXPECT_LT(q.R.row(1).dot(Vec3::UnitZ()), 0);
}

TEST(Pose, LookAtDegenerateUpStaysOrthonormal) {
  for (const Pose& p : {Pose::lookAt({0, 0, 5}, {0, 0, 0}, Vec3::UnitZ()),
                        Pose::lookAt({1, 1, 1}, {1, 1, 1}, Vec3::UnitZ())}) {
    ASSERT_TRUE(p.R.allFinite());
    EXPECT_LT((p.R * p.R.transpose() - Mat3::Identity()).norm(), kTight);
    EXPECT_NEAR(p.R.determinant(), 1.0, kTight);
  }
}

TEST(CameraModel, ProjectMatchesClosedForm) {
  const CameraModel cam = testing::makeCamera({0.5, -6, 1.2}, {0, 0, 1}, 1400);
  const Vec3 X(0.4, 0.3, 1.7);
  const Vec3 d = cam.pose.R * X + cam.pose.t;
  const double u = cam.K.fx * d.x() / d.z() + cam.K.skew * d.y() / d.z() + cam.K.cx;
  const double v = cam.K.fy * d.y() / d.z() + cam.K.cy;
  auto p = cam.project(X);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), u, kTight * 1e3);
  EXPECT_NEAR(p->y(), v, kTight * 1e3);
  // Same through the 3x4 matrix.
  auto q = projectWith(cam.projectionMatrix(), X);
  ASSERT_TRUE(q.has_value());
  EXPECT_LT((*q - *p).norm(), 1e-9);
  EXPECT_TRUE(projectionMatrix(cam.K, cam.pose) == cam.projectionMatrix());
}

TEST(CameraModel, ProjectRejectsPointsBehind) {
  const CameraModel cam = testing::makeCamera({0, -5, 1}, {0, 0, 1});
  EXPECT_FALSE(cam.project({0, -10, 1}).has_value());           // behind
  EXPECT_FALSE(cam.project(cam.pose.center()).has_value());     // at the centre
  EXPECT_FALSE(cam.project({std::nan(""), 0, 0}).has_value());  // NaN
  // On the principal plane the 3x4 projection has w = 0.
  EXPECT_FALSE(projectWith(cam.projectionMatrix(), {3, -5, 1}).has_value());
}

TEST(CameraModel, BackprojectRayPassesThroughPoint) {
  CameraModel cam = testing::makeCamera({0.8, -5, 1.4}, {0, 0, 1}, 1100);
  cam.dist = typicalLens();
  for (const Vec3& X : {Vec3(0, 0, 1), Vec3(1.2, 0.5, 0.2), Vec3(-1.5, -0.4, 2.1)}) {
    auto px = cam.project(X);
    ASSERT_TRUE(px.has_value());
    auto ray = cam.backproject(*px);
    ASSERT_TRUE(ray.has_value()) << ray.error().message;
    EXPECT_NEAR(ray->dir.norm(), 1.0, kTight);
    EXPECT_LT((ray->origin - cam.pose.center()).norm(), kTight);
    const Vec3 to = X - ray->origin;
    // Distance of X from the ray, relative to its range.
    EXPECT_LT((to - to.dot(ray->dir) * ray->dir).norm(), 1e-10 * to.norm());
    EXPECT_GT(to.dot(ray->dir), 0);
  }
}

TEST(CameraModel, UndistortPixelGivesIdealProjection) {
  CameraModel cam = testing::makeCamera({-0.8, -4, 1.0}, {0.2, 0, 1.1}, 900);
  cam.dist = typicalLens();
  CameraModel ideal = cam;
  ideal.dist = Distortion{};
  for (const Vec3& X : {Vec3(0.2, 0, 1.1), Vec3(1.3, 0.6, 0.1), Vec3(-1.1, -0.2, 1.8)}) {
    auto distorted = cam.project(X);
    auto expected = ideal.project(X);
    ASSERT_TRUE(distorted && expected);
    auto undist = cam.undistortPixel(*distorted);
    ASSERT_TRUE(undist.has_value());
    EXPECT_LT((*undist - *expected).norm(), 1e-9);
  }
  auto bad = cam.undistortPixel({std::numeric_limits<double>::infinity(), 0});
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
}

TEST(CameraModel, InImageUsesPixelCentreConvention) {
  CameraModel cam;
  cam.width = 640;
  cam.height = 480;
  EXPECT_TRUE(cam.inImage({-0.5, -0.5}));
  EXPECT_TRUE(cam.inImage({639.49, 479.49}));
  EXPECT_FALSE(cam.inImage({639.5, 10}));
  EXPECT_FALSE(cam.inImage({10, 479.5}));
  EXPECT_FALSE(cam.inImage({-0.51, 10}));
  EXPECT_FALSE(cam.inImage({std::nan(""), 10}));
}

}  // namespace
}  // namespace procam::geom
