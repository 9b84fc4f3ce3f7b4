// The display plane from points two calibrated cameras both see (calib::planeFromTwoViews):
// synthetic 640x480 cameras 0.7 m apart, 1.9 m from a wall turned 11 degrees, 80 features
// on it projected into both with 0.2 px of noise. Theory for that noise: a point's depth
// is good to about 0.2 px x sqrt(2) x 1.9 m / 620 px / sin(21 deg) = 2.4 mm, so the plane's
// offset to 2.4 / sqrt(80) = 0.27 mm and its normal, over features spread 0.37 m RMS
// across, to about 2.4 mm / (0.37 m x sqrt(80)) = 0.04 degrees per axis. Bounds: 1 mm and
// 0.15 degrees (over three standard errors of both axes).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "calibration/two_view_plane.hpp"
#include "synthetic_rig.hpp"

namespace procam::calib {
namespace {

geom::CameraModel rightCamera() {
  geom::CameraModel c = testing::camera640();
  c.dist = {-0.08, 0.02, 0.0, 0.0, 0.0};
  c.pose = geom::Pose::lookAt(Vec3(0.35, -1.9, 0.45), Vec3(0.0, 0.0, 0.45), Vec3::UnitZ());
  return c;
}

const geom::Plane kWall = testing::planeThrough(Vec3(0.0, 0.0, 0.5), Vec3(0.2, -1.0, 0.05));

// A grid of wall points both cameras see, as pixels with `noise_px` of noise.
std::vector<TwoViewPoint> wallPoints(const geom::Plane& plane, double noise_px,
                                     Points3* world = nullptr) {
  const geom::CameraModel a = testing::camera640(), b = rightCamera();
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<TwoViewPoint> out;
  for (int j = 0; j < 8; ++j) {
    for (int i = 0; i < 10; ++i) {
      // On the plane below (x, z): solve for y.
      const double x = -0.6 + 0.13 * i, z = 0.05 + 0.12 * j;
      const double y = -(plane.n.x() * x + plane.n.z() * z + plane.d) / plane.n.y();
      const Vec3 p(x, y, z);
      auto pa = a.project(p), pb = b.project(p);
      if (!pa || !pb || !a.inImage(*pa) || !b.inImage(*pb)) continue;
      out.push_back({*pa + Vec2(noise(rng), noise(rng)), *pb + Vec2(noise(rng), noise(rng))});
      if (world) world->push_back(p);
    }
  }
  return out;
}

double normalAngleDeg(const geom::Plane& fit, const geom::Plane& truth) {
  return std::acos(std::min(1.0, std::abs(fit.n.dot(truth.n)))) * 180 / M_PI;
}

TEST(TwoViewPlane, NoisyCornersGiveTheWall) {
  Points3 world;
  const auto points = wallPoints(kWall, 0.2, &world);
  ASSERT_GE(points.size(), 60u);
  auto plane = planeFromTwoViews(testing::camera640(), rightCamera(), points, "a", "b");
  ASSERT_TRUE(plane) << plane.error().message;
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : world) centre += p / double(world.size());
  const double angle = normalAngleDeg(plane->fit.plane, kWall);
  const double offset_mm = std::abs(plane->fit.plane.signedDistance(centre)) * 1000;
  std::printf("[ figures  ] %zu points: normal %.4f deg, offset %.3f mm, depth noise %.3f mm\n",
              points.size(), angle, offset_mm, plane->noise_m * 1000);
  EXPECT_EQ(plane->triangulated, points.size());
  EXPECT_LT(angle, 0.15);
  EXPECT_LT(offset_mm, 1.0);
  EXPECT_TRUE(plane->fit.plane.n.allFinite());
}

// A plane other projectors of the wall were calibrated on is kept when the points lie on
// it (within five times their depth noise), and set aside when they do not.
TEST(TwoViewPlane, APriorPlaneTheyLieOnIsKept) {
  const auto points = wallPoints(kWall, 0.2);
  geom::Plane near = kWall;
  near.d += 0.0003;
  auto kept = planeFromTwoViews(testing::camera640(), rightCamera(), points, "a", "b", near);
  ASSERT_TRUE(kept) << kept.error().message;
  EXPECT_LT((kept->fit.plane.n - near.n).norm(), 1e-12);
  EXPECT_NEAR(kept->fit.plane.d, near.d, 1e-12);
  EXPECT_GE(kept->fit.inliers.size(), 0.9 * points.size());
  geom::Plane far = kWall;
  far.d += 0.05;
  auto refit = planeFromTwoViews(testing::camera640(), rightCamera(), points, "a", "b", far);
  ASSERT_TRUE(refit) << refit.error().message;
  EXPECT_LT(std::abs(refit->fit.plane.signedDistance(Vec3(0.0, 0.0, 0.5))), 0.001);
}

// A wall 8 m away seen with 1 px of noise: the rays miss each other by about 2 cm, and
// every pair is kept (mismatches are told by the pairs' own miss distance, not by a
// fixed one).
TEST(TwoViewPlane, AFarWallKeepsEveryPair) {
  const geom::Plane far = testing::planeThrough(Vec3(0.0, 6.0, 0.5), Vec3(0.2, -1.0, 0.05));
  const auto points = wallPoints(far, 1.0);
  ASSERT_GE(points.size(), 60u);
  auto plane = planeFromTwoViews(testing::camera640(), rightCamera(), points, "a", "b");
  ASSERT_TRUE(plane) << plane.error().message;
  EXPECT_EQ(plane->triangulated, points.size());
  EXPECT_TRUE(plane->fit.plane.n.allFinite() && std::isfinite(plane->fit.plane.d));
}

TEST(TwoViewPlane, MismatchedPointsAreLeftOut) {
  auto points = wallPoints(kWall, 0.2);
  ASSERT_GE(points.size(), 60u);
  // Five features paired with the wrong one in the second camera.
  for (std::size_t k = 0; k < 5; ++k) std::swap(points[3 * k].b, points[3 * k + 40].b);
  auto plane = planeFromTwoViews(testing::camera640(), rightCamera(), points, "a", "b");
  ASSERT_TRUE(plane) << plane.error().message;
  EXPECT_LT(normalAngleDeg(plane->fit.plane, kWall), 0.15);
  EXPECT_LE(plane->fit.inliers.size(), points.size() - 10);
}

TEST(TwoViewPlane, TwoWallsAreNotOnePlane) {
  // Half the points on a second wall at right angles to the first (a corner).
  const geom::Plane side = testing::planeThrough(Vec3(0.0, 0.0, 0.5), Vec3(1.0, 0.2, 0.0));
  auto points = wallPoints(kWall, 0.2);
  auto more = wallPoints(testing::planeThrough(Vec3(0.0, 0.3, 0.5), side.n), 0.2);
  ASSERT_FALSE(more.empty());
  points.insert(points.end(), more.begin(), more.end());
  auto plane = planeFromTwoViews(testing::camera640(), rightCamera(), points, "cam", "cam2");
  ASSERT_FALSE(plane);
  EXPECT_EQ(plane.error().code, ErrorCode::kDegenerate);
  EXPECT_NE(plane.error().message.find("not a plane"), std::string::npos) << plane.error().message;
}

// Cameras 2 cm apart at 1.9 m: their rays meet at about 0.6 degrees.
TEST(TwoViewPlane, TooShortABaselineIsRefused) {
  geom::CameraModel near = testing::camera640();
  near.pose = geom::Pose::lookAt(Vec3(-0.33, -1.9, 0.45), Vec3(0.0, 0.0, 0.45), Vec3::UnitZ());
  std::vector<TwoViewPoint> points;
  for (const TwoViewPoint& p : wallPoints(kWall, 0.0)) {
    auto a = testing::camera640().backproject(p.a);
    ASSERT_TRUE(a);
    auto hit = geom::intersectPlane(*a, kWall);
    ASSERT_TRUE(hit);
    auto b = near.project(hit->point);
    if (b) points.push_back({p.a, *b});
  }
  ASSERT_GE(points.size(), 8u);
  auto plane = planeFromTwoViews(testing::camera640(), near, points, "a", "b");
  ASSERT_FALSE(plane);
  EXPECT_EQ(plane.error().code, ErrorCode::kIllConditioned) << plane.error().message;
}

TEST(TwoViewPlane, TooFewOrBrokenPointsAreRefused) {
  auto points = wallPoints(kWall, 0.0);
  points.resize(7);
  auto few = planeFromTwoViews(testing::camera640(), rightCamera(), points, "a", "b");
  ASSERT_FALSE(few);
  EXPECT_EQ(few.error().code, ErrorCode::kTooFewPoints);
  // Non-finite pixels are dropped, not triangulated.
  auto broken = wallPoints(kWall, 0.0);
  for (std::size_t k = 0; k < broken.size(); k += 2) broken[k].a.x() = std::nan("");
  auto plane = planeFromTwoViews(testing::camera640(), rightCamera(), broken, "a", "b");
  ASSERT_TRUE(plane) << plane.error().message;
  EXPECT_EQ(plane->triangulated, broken.size() / 2);
  EXPECT_TRUE(plane->fit.plane.n.allFinite() && std::isfinite(plane->fit.plane.d));
}

}  // namespace
}  // namespace procam::calib
