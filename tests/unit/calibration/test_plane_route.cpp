#include <gtest/gtest.h>

#include "calibration/projector_calibration.hpp"
#include "geometry/projection_matrix.hpp"
#include "synthetic_rig.hpp"

using namespace procam;
using namespace procam::calib;
using procam::testing::litPoint;
using procam::testing::planeThrough;

namespace {

// One orientation of a blank plane: projector pixels every `step` px that land on
// it and are seen by the camera, with the camera pixel (distorted) that sees them.
// Decoding noise of sigma projector pixels on the projector side.
PlaneView planeView(const geom::CameraModel& projector, const geom::CameraModel& camera,
                    const geom::Plane& plane, int step, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, sigma);
  PlaneView v;
  for (int y = 0; y < projector.height; y += step)
    for (int x = 0; x < projector.width; x += step) {
      auto p = litPoint(projector, Vec2(x, y), plane);
      if (!p) continue;
      auto c = camera.project(*p);
      if (!c || !camera.inImage(*c)) continue;
      v.camera.push_back(*c);
      v.projector.emplace_back(x + noise(rng), y + noise(rng));
    }
  return v;
}

// The wall in front of the projector at two orientations (turned 25 degrees about
// a vertical and 20 degrees about a horizontal axis).
std::vector<PlaneView> twoOrientations(double sigma) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  const Vec3 centre(0.0, 0.3, 0.5);
  const Vec3 n1 = Eigen::AngleAxisd(0.44, Vec3::UnitZ()) * Vec3(0, -1, 0);
  const Vec3 n2 = Eigen::AngleAxisd(-0.35, Vec3::UnitX()) * Vec3(0, -1, 0);
  return {planeView(projector, camera, planeThrough(centre, n1), 8, sigma, 1),
          planeView(projector, camera, planeThrough(centre, n2), 8, sigma, 2)};
}

}  // namespace

// The intrinsics accuracy bounds for route (b): focal 0.5%, principal point 2 px
// (c_x is the assumed image centre, exact for this projector).
TEST(RouteB, TwoPlaneOrientationsGiveTheIntrinsics) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  const auto views = twoOrientations(0.05);
  ASSERT_GT(views[0].camera.size(), 2000u);
  ASSERT_GT(views[1].camera.size(), 2000u);
  // The distance from the camera centre to the first plane fixes the scale.
  const Vec3 n1 = Eigen::AngleAxisd(0.44, Vec3::UnitZ()) * Vec3(0, -1, 0);
  const geom::Plane first = planeThrough(Vec3(0.0, 0.3, 0.5), n1);
  PlaneRouteOptions options;
  options.projector_width = projector.width;
  options.projector_height = projector.height;
  options.first_plane_distance = std::abs(first.signedDistance(camera.pose.center()));
  auto c = calibrateProjectorFromPlanes(camera, views, options);
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_NEAR(c->K.fx, projector.K.fx, 0.005 * projector.K.fx);
  EXPECT_NEAR(c->K.fy, projector.K.fy, 0.005 * projector.K.fy);
  EXPECT_NEAR(c->K.cx, projector.K.cx, 2.0);
  EXPECT_NEAR(c->K.cy, projector.K.cy, 2.0);
  EXPECT_TRUE(c->scale_known);
  EXPECT_LT((c->pose.center() - projector.pose.center()).norm(), 0.002);
  EXPECT_LT(Eigen::AngleAxisd(c->pose.R.transpose() * projector.pose.R).angle() * 180 / M_PI, 0.05);
  // Noise of 0.05 px per coordinate: the RMS of the 2D residual is about 0.05*sqrt(2).
  EXPECT_LT(c->rms_px, 0.1);
}

TEST(RouteB, WithoutADistanceTheTranslationIsADirection) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  PlaneRouteOptions options;
  options.projector_width = projector.width;
  options.projector_height = projector.height;
  auto c = calibrateProjectorFromPlanes(camera, twoOrientations(0.05), options);
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_FALSE(c->scale_known);
  EXPECT_NEAR(c->K.fx, projector.K.fx, 0.005 * projector.K.fx);
  EXPECT_NEAR(c->K.cy, projector.K.cy, 2.0);
  const Vec3 true_dir = (projector.pose.R * camera.pose.center() + projector.pose.t)
                            .normalized();  // camera in projector frame
  const Vec3 est_dir = (c->pose.R * camera.pose.center() + c->pose.t).normalized();
  EXPECT_LT((true_dir - est_dir).norm(), 1e-3);
}

TEST(RouteB, OneOrientationOrParallelPlanesAreRejected) {
  const auto camera = procam::testing::camera640();
  auto views = twoOrientations(0.05);
  EXPECT_EQ(calibrateProjectorFromPlanes(camera, std::span(views).first(1)).error().code,
            ErrorCode::kTooFewPoints);
  const auto projector = procam::testing::squarePixelProjector();
  const Vec3 n = Eigen::AngleAxisd(0.44, Vec3::UnitZ()) * Vec3(0, -1, 0);
  std::vector<PlaneView> parallel = {
      views[0], planeView(projector, camera, planeThrough(Vec3(0.0, 0.45, 0.5), n), 8, 0.05, 5)};
  auto c = calibrateProjectorFromPlanes(camera, parallel);
  ASSERT_FALSE(c);
  EXPECT_TRUE(c.error().code == ErrorCode::kDegenerate ||
              c.error().code == ErrorCode::kNoConvergence)
      << c.error().message;
}

// Why route (b) fixes three intrinsics: with the camera frame as reference, for any
// w the projector K'R' = KR + (Kt) w^T, t' = K'^-1 K t seeing the planes m_i' = m_i - w
// (m_i . X = 1) reproduces every correspondence of every plane exactly, while K'
// has skew, non-square pixels and a shifted c_x (plane_route.cpp).
TEST(RouteB, BlankPlanesLeaveAThreeParameterFamilyOfIntrinsics) {
  const auto projector = procam::testing::squarePixelProjector();
  const auto camera = procam::testing::camera640();
  // The projector in the camera frame: x_p = R x_c + t.
  const Mat3 R = projector.pose.R * camera.pose.R.transpose();
  const Vec3 t = projector.pose.t - R * camera.pose.t;
  const Mat3 K = projector.K.matrix();
  const Vec3 centre(0.0, 0.3, 0.5);
  std::vector<geom::Plane> planes = {
      planeThrough(centre, Eigen::AngleAxisd(0.44, Vec3::UnitZ()) * Vec3(0, -1, 0)),
      planeThrough(centre, Eigen::AngleAxisd(-0.35, Vec3::UnitX()) * Vec3(0, -1, 0))};
  for (const Vec3& w : {Vec3(0.03, -0.02, 0.01), Vec3(-0.05, 0.04, -0.03)}) {
    Mat34 P;
    P.leftCols<3>() = K * R + K * t * w.transpose();
    P.col(3) = K * t;
    auto alt = geom::decomposeProjectionMatrix(P);
    ASSERT_TRUE(alt);
    const Mat3 K2 = alt->K.matrix();
    // Far outside what the route's tolerances would accept as the same projector.
    EXPECT_GT(std::abs(alt->K.skew) + std::abs(alt->K.fx - alt->K.fy) +
                  std::abs(alt->K.cx - projector.K.cx),
              20.0);
    double worst = 0;
    int n = 0;
    for (const geom::Plane& plane : planes) {
      // Plane in the camera frame as m . x_c = 1.
      const Vec3 n_c = camera.pose.R * plane.n;
      const Vec3 m = n_c / (n_c.dot(camera.pose.t) - plane.d);
      const Vec3 m2 = m - w;
      for (int y = 0; y < projector.height; y += 64)
        for (int x = 0; x < projector.width; x += 64) {
          auto X = procam::testing::litPoint(projector, Vec2(x, y), plane);
          ASSERT_TRUE(X);
          const Vec3 ray = camera.pose.toDevice(*X);  // the camera sees X along this ray
          const Vec3 seen = K2 * (alt->pose.R * (ray / m2.dot(ray)) + alt->pose.t);
          worst = std::max(worst, (seen.hnormalized() - Vec2(x, y)).norm());
          ++n;
        }
    }
    EXPECT_GT(n, 200);
    EXPECT_LT(worst, 1e-6);
  }
}
