#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/units.hpp"
#include "keystone/keystone_solver.hpp"
#include "keystone/orientation.hpp"

namespace procam::keystone {
namespace {

KeystoneProblem problem(const Angles& a) {
  KeystoneProblem p;
  p.K = {1600, 1600, 959.5, 539.5, 0};
  p.width = 1920;
  p.height = 1080;
  p.content_width = 1920;
  p.content_height = 1080;
  p.R = rotationFromAngles(a);
  return p;
}

// Ground truth: where framebuffer pixel x lands on the wall Y = 1 (wall X, Z).
Vec2 onWall(const KeystoneProblem& p, const Vec2& x) {
  const Vec3 ray = p.R.transpose() * (p.K.matrix().inverse() * x.homogeneous());
  return Vec2(ray.x() / ray.y(), ray.z() / ray.y());
}

TEST(KeystoneSolver, SquareProjectorNeedsNoWarp) {
  auto s = solveKeystone(problem({}));
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_NEAR((s->H - Mat3::Identity()).norm(), 0, 1e-12);
  EXPECT_NEAR((s->corners[0] - Vec2(-0.5, -0.5)).norm(), 0, 1e-9);
  EXPECT_NEAR((s->corners[2] - Vec2(1919.5, 1079.5)).norm(), 0, 1e-9);
  EXPECT_NEAR(s->scale, 1, 1e-12);
}

TEST(KeystoneSolver, DisplayedImageIsAnUprightRectangleOfTheContentAspect) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pitch(-45, 45), roll(-20, 20), yaw(-30, 30);
  for (int i = 0; i < 100; ++i) {
    KeystoneProblem p = problem({pitch(rng) * kDeg, roll(rng) * kDeg, yaw(rng) * kDeg});
    if (i % 3 == 0) p.content_width = 1440;  // 4:3 content
    auto s = solveKeystone(p);
    ASSERT_TRUE(s) << s.error().message;
    std::array<Vec2, 4> w;
    for (int k = 0; k < 4; ++k) {
      w[k] = onWall(p, s->corners[k]);
      // Inside the framebuffer (the projector can show it).
      EXPECT_GE(s->corners[k].x(), -0.5 - 1e-6);
      EXPECT_LE(s->corners[k].x(), 1919.5 + 1e-6);
      EXPECT_GE(s->corners[k].y(), -0.5 - 1e-6);
      EXPECT_LE(s->corners[k].y(), 1079.5 + 1e-6);
    }
    const double scale = (w[1] - w[0]).norm();
    // TL-TR and BL-BR horizontal, TL-BL and TR-BR vertical, top above bottom.
    EXPECT_NEAR(w[0].y(), w[1].y(), 1e-9 * scale);
    EXPECT_NEAR(w[3].y(), w[2].y(), 1e-9 * scale);
    EXPECT_NEAR(w[0].x(), w[3].x(), 1e-9 * scale);
    EXPECT_NEAR(w[1].x(), w[2].x(), 1e-9 * scale);
    EXPECT_GT(w[0].y(), w[3].y());
    EXPECT_LT(w[0].x(), w[1].x());
    const double aspect = (w[1].x() - w[0].x()) / (w[0].y() - w[3].y());
    EXPECT_NEAR(aspect, double(p.content_width) / p.content_height, 1e-9);
    // H maps every content pixel edge corner to those framebuffer corners.
    const Vec2 br(p.content_width - 0.5, p.content_height - 0.5);
    EXPECT_NEAR(((s->H * br.homogeneous()).hnormalized() - s->corners[2]).norm(), 0, 1e-9);
    // Largest: at least two corners touch the quadrilateral's edges (a corner on the
    // framebuffer border), else it could grow.
    int touching = 0;
    for (int k = 0; k < 4; ++k) {
      const Vec2& c = s->corners[k];
      touching += std::min({std::abs(c.x() + 0.5), std::abs(c.x() - 1919.5), std::abs(c.y() + 0.5),
                            std::abs(c.y() - 1079.5)}) < 1e-6;
    }
    EXPECT_GE(touching, 2);
    EXPECT_GT(s->scale, 0.3);
    EXPECT_LE(s->scale, 1 + 1e-12);
  }
}

TEST(KeystoneSolver, VerticalKeystoneIsSymmetric) {
  auto s = solveKeystone(problem({20 * kDeg, 0, 0}));
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->corners[0].x() + s->corners[1].x(), 1919, 1e-9);
  EXPECT_NEAR(s->corners[3].x() + s->corners[2].x(), 1919, 1e-9);
  // Tilted up, the image widens at the top: the top edge is the narrower one in
  // the framebuffer.
  EXPECT_LT(s->corners[1].x() - s->corners[0].x(), s->corners[2].x() - s->corners[3].x());
}

TEST(KeystoneSolver, TypedErrors) {
  KeystoneProblem p = problem({80 * kDeg, 0, 0});
  EXPECT_EQ(solveKeystone(p).error().code, ErrorCode::kDegenerate);  // top misses the wall
  p = problem({});
  p.width = 0;
  EXPECT_EQ(solveKeystone(p).error().code, ErrorCode::kInvalidInput);
  p = problem({});
  p.R(0, 0) = NAN;
  EXPECT_EQ(solveKeystone(p).error().code, ErrorCode::kInvalidInput);
  p = problem({});
  p.K.fx = -1;
  EXPECT_EQ(solveKeystone(p).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::keystone
