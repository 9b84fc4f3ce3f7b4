// Tilt-only automatic keystone (keystone/keystone_from_down.hpp): the pre-warp for a
// direction of gravity is the keystone solve at the pitch and roll it gives.
#include <gtest/gtest.h>

#include "core/units.hpp"
#include "keystone/keystone_from_down.hpp"
#include "keystone/keystone_solver.hpp"

namespace procam::keystone {
namespace {

TEST(SolveFromDown, EqualsTheKeystoneSolveAtThatTilt) {
  ProjectorModel p;
  p.K = geom::Intrinsics{1400, 1400, 639.5, 359.5, 0};
  p.width = 1280;
  p.height = 720;
  const Angles a{-15 * kDeg, 9 * kDeg, 0};
  const Mat3 R = rotationFromAngles(a);
  const Vec3 down = R * Vec3(0, 0, -1);
  auto e = solveFromDown(p, down, 1920, 1080);
  ASSERT_TRUE(e) << e.error().message;
  KeystoneProblem problem{p.K, 1280, 720, R, 1920, 1080, {}};
  auto truth = solveKeystone(problem);
  ASSERT_TRUE(truth);
  EXPECT_LT((e->H - truth->H).cwiseAbs().maxCoeff(), 1e-9 * truth->H.cwiseAbs().maxCoeff());
  EXPECT_NEAR(e->angles.pitch, a.pitch, 1e-12);
  EXPECT_NEAR(e->angles.roll, a.roll, 1e-12);
  EXPECT_EQ(e->content_width, 1920);
  // Tilted so far that part of the frame misses the wall: an error, not NaN.
  const Vec3 up_steep = rotationFromAngles({89 * kDeg, 0, 0}) * Vec3(0, 0, -1);
  EXPECT_FALSE(solveFromDown(p, up_steep, 1280, 720));
}

}  // namespace
}  // namespace procam::keystone
