#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "keystone/head_tracked.hpp"

namespace procam::keystone {
namespace {

// Random planar scene: display plane through `origin` with axes u (right), v (up), an
// oblique projector, a viewer in front of the plane.
struct Scene {
  Vec3 origin, u, v, n;
  Mat34 P;
  int W = 1280, H = 800;
};

Scene randomScene(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  Scene s;
  const Mat3 plane_rot = Eigen::AngleAxisd(M_PI * U(rng), Vec3(U(rng), U(rng), U(rng)).normalized())
                             .toRotationMatrix();
  s.origin = Vec3(U(rng), U(rng), U(rng));
  s.u = plane_rot.col(0);
  s.v = plane_rot.col(1);
  s.n = plane_rot.col(2);  // towards the viewer
  // Projector 2-3 m in front, aimed at the plane with up to 35° of obliqueness.
  const Vec3 dir =
      (-s.n + 0.7 * std::tan(35 * M_PI / 180) * (U(rng) * s.u + U(rng) * s.v)).normalized();
  const Vec3 centre = s.origin - (2.5 + 0.5 * U(rng)) * dir + 0.3 * (U(rng) * s.u + U(rng) * s.v);
  // Device frame: z along dir, y down roughly along -v, rolled a little.
  const Vec3 z = dir;
  Vec3 x = (-s.v + 0.2 * U(rng) * s.u).cross(z).normalized();
  const Vec3 y = z.cross(x);
  Mat3 R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  Mat3 K;
  K << 1500 * (1 + 0.2 * U(rng)), 0, 639.5 + 50 * U(rng), 0, 1500, 399.5 + 200 * U(rng), 0, 0, 1;
  s.P << K * R, -K * R * centre;
  return s;
}

TEST(HeadTracked, SinglePassEqualsRenderThenWarpAndKeepsDepthInRange) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> U(-1, 1), U01(0, 1);
  for (int scene = 0; scene < 50; ++scene) {
    const Scene s = randomScene(rng);
    auto S = boundingDisplayRect(s.P, s.W, s.H, s.origin, s.u, s.v);
    ASSERT_TRUE(S) << S.error().message;
    const Vec3 centre = S->corner + 0.5 * S->width * S->u + 0.5 * S->height * S->v;
    for (int viewer = 0; viewer < 10; ++viewer) {
      const Vec3 eye = centre + (1 + 2 * U01(rng)) * s.n + 1.5 * (U(rng) * s.u + U(rng) * s.v);
      const double near = 0.1, far = 20;
      auto path = headTrackedPath(eye, *S, near, far, s.P, s.W, s.H);
      ASSERT_TRUE(path) << path.error().message;
      for (int k = 0; k < 50; ++k) {
        // A virtual point inside the frustum of S, in front of or behind the plane.
        const Vec3 on_S = S->corner + U01(rng) * S->width * S->u + U01(rng) * S->height * S->v;
        const double dist = (on_S - eye).dot(-s.n);  // depth of S along the view axis
        const double depth = near + (far - near) * U01(rng);
        const Vec3 V = eye + (depth / dist) * (on_S - eye);
        // Two steps: render with P_T, then warp with A.
        const Vec4 mT = path->P_T * V.homogeneous();
        const Vec2 ndcT = mT.head<2>() / mT.w();
        ASSERT_LE(ndcT.cwiseAbs().maxCoeff(), 1 + 1e-9);
        const Vec2 two_step = ndcToPixel((path->A * ndcT.homogeneous()).hnormalized(), s.W, s.H);
        // One pass.
        const Vec4 m = path->single_pass * V.homogeneous();
        ASSERT_GT(m.w(), 0);
        const Vec2 one_pass = ndcToPixel(m.head<2>() / m.w(), s.W, s.H);
        EXPECT_NEAR((one_pass - two_step).norm(), 0, 1e-7);
        EXPECT_GE(m.z() / m.w(), -1 - 1e-12);
        EXPECT_LE(m.z() / m.w(), 1 + 1e-12);
        // Ground truth: the viewer's line of sight through V meets the plane at M; the
        // projector pixel lighting M is where V must be drawn (§4.2.1).
        const Vec3 ray = V - eye;
        const Vec3 M = eye + ray * (s.n.dot(s.origin - eye) / s.n.dot(ray));
        const Vec2 truth = (s.P * M.homogeneous()).hnormalized();
        EXPECT_NEAR((one_pass - truth).norm(), 0, 1e-6);
      }
    }
  }
}

TEST(HeadTracked, DepthScaleOfEquation410) {
  Mat3 A;
  A << 1.1, 0.1, 0.05, -0.02, 0.9, 0.1, 0.2, -0.3, 1;
  auto M = singlePassMatrix(2 * A);  // scale of A is irrelevant
  ASSERT_TRUE(M);
  EXPECT_NEAR((*M)(2, 2), 1 - 0.2 - 0.3, 1e-15);
  EXPECT_NEAR((*M)(3, 0), 0.2, 1e-15);
  EXPECT_NEAR((*M)(0, 3), 0.05, 1e-15);
  A(2, 0) = 0.8;
  EXPECT_EQ(singlePassMatrix(A).error().code, ErrorCode::kIllConditioned);
}

TEST(HeadTracked, TypedErrors) {
  DisplayRect S;
  EXPECT_EQ(offAxisProjection(Vec3(0.5, 0.5, -1), S, 0.1, 10).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(offAxisProjection(Vec3(0.5, 0.5, 1), S, 1, 0.5).error().code, ErrorCode::kInvalidInput);
  S.width = -1;
  EXPECT_EQ(offAxisProjection(Vec3(0.5, 0.5, 1), S, 0.1, 10).error().code,
            ErrorCode::kInvalidInput);
  Mat34 P = Mat34::Zero();
  P.leftCols<3>() = Mat3::Identity();  // looks along +z, plane z = 0 through its centre
  EXPECT_EQ(
      boundingDisplayRect(P, 100, 100, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()).error().code,
      ErrorCode::kDegenerate);
}

}  // namespace
}  // namespace procam::keystone
