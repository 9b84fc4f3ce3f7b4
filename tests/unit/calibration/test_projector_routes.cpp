#include <gtest/gtest.h>

#include <algorithm>

#include "calibration/projector_calibration.hpp"
#include "route_tolerances.hpp"
#include "synthetic_rig.hpp"

using namespace procam;
using namespace procam::calib;
using procam::testing::expectMatches;
using procam::testing::litPoint;
using procam::testing::planeThrough;

namespace {

// Two walls meeting in a vertical corner in front of the projector, sampled every
// `step` projector pixels, with Gaussian noise on the 3D points.
surface::SurfacePoints cornerPoints(const geom::CameraModel& projector, int step, double sigma_m,
                                    bool planar) {
  const geom::Plane left = planeThrough(Vec3(0, 0.5, 0), Vec3(1, -1, 0));
  const geom::Plane right = planeThrough(Vec3(0, 0.5, 0), Vec3(-1, -1, 0));
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, sigma_m);
  surface::SurfacePoints pts;
  pts.step = step;
  for (int v = 0; v < projector.height; v += step)
    for (int u = 0; u < projector.width; u += step) {
      auto a = litPoint(projector, Vec2(u, v), left);
      auto b = litPoint(projector, Vec2(u, v), right);
      std::optional<Vec3> x;
      if (planar)
        x = a;
      else if (a && b)
        x = (a->y() < b->y()) ? a : b;  // the nearer wall to the projector along +y
      if (!x) continue;
      pts.world.push_back(*x + Vec3(noise(rng), noise(rng), noise(rng)));
      pts.projector.emplace_back(u, v);
    }
  return pts;
}

}  // namespace

TEST(RouteA, CornerSurfaceRecoversTheProjector) {
  const auto truth = procam::testing::projector1024();
  // 0.1 mm triangulation noise per axis (a sub-pixel stereo pair at 2 m): about
  // 0.065 px per projector axis at f = 1500, so the 2D RMS stays under 0.15 px.
  auto pts = cornerPoints(truth, 16, 0.0001, false);
  ASSERT_GT(pts.world.size(), 1000u);
  auto c = calibrateProjectorFromSurface(pts);
  ASSERT_TRUE(c) << c.error().message;
  expectMatches(*c, truth);
  EXPECT_LE(c->rms_px, 0.15);
  // Gaussian noise: a 3-sigma cut on the 2D residual norm keeps exp(-4.5), ~99%, per round.
  ASSERT_EQ(c->inliers.size(), pts.world.size());
  EXPECT_GT(c->points, static_cast<int>(0.97 * pts.world.size()));
  EXPECT_EQ(c->points, static_cast<int>(std::count(c->inliers.begin(), c->inliers.end(), 1)));
}

TEST(RouteA, PlanarSurfaceIsTheCoplanarError) {
  const auto truth = procam::testing::projector1024();
  auto pts = cornerPoints(truth, 16, 0.0001, true);
  auto c = calibrateProjectorFromSurface(pts);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().code, ErrorCode::kCoplanar);
  EXPECT_NE(c.error().message.find("non-planar"), std::string::npos);
  EXPECT_NE(c.error().message.find("route b"), std::string::npos);
}

TEST(RouteC, SixFiducialsOnAnObject) {
  const auto truth = procam::testing::projector1024();
  // Corners of a box and points on a pedestal (not coplanar), seen exactly.
  const Points3 world = {{-0.3, 0.4, 0.2}, {0.3, 0.4, 0.2},  {0.3, 0.8, 0.2},    {-0.3, 0.8, 0.9},
                         {0.0, 0.5, 0.75}, {0.25, 0.6, 0.5}, {-0.2, 0.55, 0.45}, {0.1, 0.7, 0.3}};
  Points2 pixels;
  for (const Vec3& x : world) pixels.push_back(*truth.project(x));
  auto c = calibrateProjectorFromFiducials(world, pixels);
  ASSERT_TRUE(c) << c.error().message;
  expectMatches(*c, truth);
  EXPECT_LT(c->rms_px, 1e-6);

  EXPECT_EQ(calibrateProjectorFromFiducials(std::span(world).first(5), std::span(pixels).first(5))
                .error()
                .code,
            ErrorCode::kTooFewPoints);
  Points3 flat = world;
  for (Vec3& x : flat) x.y() = 0.6;
  Points2 flat_pixels;
  for (const Vec3& x : flat) flat_pixels.push_back(*truth.project(x));
  EXPECT_EQ(calibrateProjectorFromFiducials(flat, flat_pixels).error().code, ErrorCode::kCoplanar);
}
