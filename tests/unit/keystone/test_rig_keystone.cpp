// Keystone from the rig model's plane mapping against the tilt solver on the same
// exact geometry: a projector's collineation with a vertical wall, built from its
// true K and pose, must give the very solution solveKeystone gives from K and R
// (both put the largest upright rectangle of the content's aspect in the image;
// the inscribed rectangle is invariant under the similarity between their wall
// coordinates), so only rounding separates them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/units.hpp"
#include "geometry/plane_homography.hpp"
#include "keystone/orientation.hpp"
#include "keystone/rig_keystone.hpp"

namespace procam::keystone {
namespace {

const geom::Intrinsics kK = {1600, 1600, 959.5, 539.5, 0};
const geom::Plane kWall = {Vec3(0, 1, 0), -2.5};  // y = 2.5, the wall frame's wall

struct Geometry {
  KeystoneProblem tilt;  // K, R: what solveKeystone needs
  RigKeystoneProblem rig;
};

// A projector at `position` turned by `a` from square to the wall.
Geometry setup(const Angles& a, const Vec3& position, int content_w, int content_h) {
  Geometry s;
  s.tilt.K = kK;
  s.tilt.width = s.rig.width = 1920;
  s.tilt.height = s.rig.height = 1080;
  s.tilt.R = rotationFromAngles(a);
  s.tilt.content_width = s.rig.content_width = content_w;
  s.tilt.content_height = s.rig.content_height = content_h;
  const geom::Pose pose{s.tilt.R, -s.tilt.R * position};
  auto basis = geom::uprightBasis(kWall, position, Vec3(0.3, 0, 1.2));
  EXPECT_TRUE(basis);
  auto to_image = geom::planeToImage(kK, pose, *basis);
  EXPECT_TRUE(to_image);
  s.rig.projector_to_plane = {*basis, to_image->inverse()};
  return s;
}

void expectSameCorners(const KeystoneSolution& a, const KeystoneSolution& b) {
  for (int i = 0; i < 4; ++i) {
    // Rounding only: the two solutions' wall coordinates differ by a similarity.
    EXPECT_NEAR((a.corners[i] - b.corners[i]).norm(), 0, 1e-6) << "corner " << i;
  }
  EXPECT_NEAR(a.scale, b.scale, 1e-9);
}

TEST(RigKeystone, MatchesTheTiltSolverOnExactGeometry) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pitch(-25, 25), roll(-10, 10), yaw(-35, 35);
  for (int i = 0; i < 40; ++i) {
    const Angles a{pitch(rng) * kDeg, roll(rng) * kDeg, yaw(rng) * kDeg};
    const Geometry s = setup(a, Vec3(0.7, -0.2, 1.1), i % 2 ? 1440 : 1920, 1080);
    auto tilt = solveKeystone(s.tilt);
    auto rig = solveRigKeystone(s.rig);
    ASSERT_TRUE(tilt) << tilt.error().message;
    ASSERT_TRUE(rig) << rig.error().message;
    expectSameCorners(*tilt, *rig);
    // The rig's wall coordinates are metres: the rectangle is the tilt solver's
    // (wall at distance 1) times the projector's distance to the wall, 2.7 m.
    EXPECT_NEAR(rig->rect.half_height, 2.7 * tilt->rect.half_height, 1e-9);
  }
}

// The stored basis need not be upright: turned in the plane and moved, the
// solution is the same.
TEST(RigKeystone, AnyBasisOfThePlaneGivesTheSameSolution) {
  Geometry s = setup({10 * kDeg, 4 * kDeg, -25 * kDeg}, Vec3(-0.4, 0.1, 0.8), 1920, 1080);
  auto reference = solveRigKeystone(s.rig);
  ASSERT_TRUE(reference) << reference.error().message;
  const geom::PlaneBasis& b = s.rig.projector_to_plane.basis;
  const Eigen::AngleAxisd turn(40 * kDeg, b.normal());
  const geom::PlaneBasis turned{b.origin + 0.3 * b.u - 0.2 * b.v, turn * b.u, turn * b.v};
  auto change = geom::changeOfBasis(b, turned);
  ASSERT_TRUE(change) << change.error().message;
  s.rig.projector_to_plane = {turned, *change * s.rig.projector_to_plane.H};
  s.rig.projector_to_plane.H *= -3.0;  // a collineation's scale and sign are free
  auto moved = solveRigKeystone(s.rig);
  ASSERT_TRUE(moved) << moved.error().message;
  expectSameCorners(*reference, *moved);
}

TEST(RigKeystone, TypedErrors) {
  const Geometry good = setup({5 * kDeg, 0, 20 * kDeg}, Vec3(0, 0, 1), 1920, 1080);
  ASSERT_TRUE(solveRigKeystone(good.rig));

  // A floor has no upright direction.
  Geometry flat = good;
  flat.rig.projector_to_plane.basis = {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()};
  auto r = solveRigKeystone(flat.rig);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate) << r.error().message;

  // Tilted up 80 degrees the top of the image passes over the wall's horizon.
  const Geometry steep = setup({80 * kDeg, 0, 0}, Vec3(0, 0, 1), 1920, 1080);
  r = solveRigKeystone(steep.rig);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kDegenerate) << r.error().message;

  Geometry skewed = good;
  skewed.rig.projector_to_plane.basis.v = Vec3(0.1, 0, 1);
  r = solveRigKeystone(skewed.rig);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  Geometry singular = good;
  singular.rig.projector_to_plane.H.row(2).setZero();
  r = solveRigKeystone(singular.rig);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  Geometry empty = good;
  empty.rig.content_width = 0;
  EXPECT_EQ(solveRigKeystone(empty.rig).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::keystone
