// Dome-master content (render/dome_master.hpp): the azimuthal equidistant fisheye of
// the sky around the eye, zenith at the centre, front at the bottom, right at the right;
// and the lookup warp of a projector lighting a ceiling onto it.
#include <gtest/gtest.h>

#include <cmath>

#include "render/dome_master.hpp"
#include "render/warp_map.hpp"

namespace procam::render {
namespace {

TEST(DomeMaster, ZenithFrontAndRightWhereTheConventionPutsThem) {
  auto m = domeMaster(Vec3(0.5, -1, 0.2), Vec3(0, 2, 0.7), 180, {1024, 1024});
  ASSERT_TRUE(m) << m.error().message;
  const Vec3 eye(0.5, -1, 0.2);
  const Vec2 centre(511.5, 511.5);
  // The zenith at the centre; the horizon on the circle (radius 512), the front (+Y) at
  // the bottom, the right (+X for a viewer facing +Y) at the right.
  EXPECT_LT((*m->contentPixel(eye + Vec3(0, 0, 3)) - centre).norm(), 1e-9);
  EXPECT_LT((*m->contentPixel(eye + Vec3(0, 2, 0)) - Vec2(511.5, 1023.5)).norm(), 1e-9);
  EXPECT_LT((*m->contentPixel(eye + Vec3(2, 0, 0)) - Vec2(1023.5, 511.5)).norm(), 1e-9);
  EXPECT_LT((*m->contentPixel(eye + Vec3(0, -2, 0)) - Vec2(511.5, -0.5)).norm(), 1e-9);
  // 45 degrees up toward the front: half way out.
  EXPECT_LT((*m->contentPixel(eye + Vec3(0, 1, 1)) - Vec2(511.5, 511.5 + 256)).norm(), 1e-9);
  // Below the horizon, and the eye itself: nothing.
  EXPECT_FALSE(m->contentPixel(eye + Vec3(1, 0, -0.1)));
  EXPECT_FALSE(m->contentPixel(eye));
  // direction() inverts contentPixel() over the circle; outside it, nothing.
  for (const Vec2& c : {Vec2(511.5, 511.5), Vec2(100, 600), Vec2(900, 300), Vec2(20, 511.5)}) {
    const auto d = m->direction(c);
    ASSERT_TRUE(d) << c.transpose();
    EXPECT_NEAR(d->norm(), 1, 1e-12);
    EXPECT_LT((*m->contentPixel(eye + 2 * *d) - c).norm(), 1e-9) << c.transpose();
  }
  EXPECT_FALSE(m->direction(Vec2(0, 0)));
}

TEST(DomeMaster, AWiderFieldAndANonSquareImage) {
  // 220 degrees on 2048 x 1024: the circle's radius is 512, centred on the image.
  auto m = domeMaster(Vec3::Zero(), Vec3(1, 0, 0), 220, {2048, 1024});
  ASSERT_TRUE(m);
  EXPECT_DOUBLE_EQ(m->radius(), 512);
  // Front +X at the bottom; 10 degrees below the horizon still inside.
  const double below = -std::tan(10 * M_PI / 180);
  const auto c = m->contentPixel(Vec3(1, 0, below));
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->x(), 1023.5, 1e-9);
  EXPECT_NEAR(c->y(), 511.5 + 512 * 100.0 / 110.0, 1e-9);
  EXPECT_FALSE(m->contentPixel(Vec3(1, 0, -std::tan(25 * M_PI / 180))));
  // A full sphere: the nadir is on the rim (at the front's point of it), not the centre.
  auto sphere = domeMaster(Vec3::Zero(), Vec3(1, 0, 0), 360, {1024, 1024});
  ASSERT_TRUE(sphere);
  const auto nadir = sphere->contentPixel(Vec3(0, 0, -2));
  ASSERT_TRUE(nadir);
  EXPECT_LT((*nadir - Vec2(511.5, 1023.5)).norm(), 1e-9);
  EXPECT_LT((*sphere->contentPixel(Vec3(0, 0, 2)) - Vec2(511.5, 511.5)).norm(), 1e-9);
}

TEST(DomeMaster, BadArgumentsAreRefused) {
  EXPECT_EQ(domeMaster(Vec3::Zero(), Vec3(0, 0, 1), 180, {10, 10}).error().code,
            ErrorCode::kInvalidInput);  // a vertical front
  EXPECT_EQ(domeMaster(Vec3::Zero(), Vec3(0, 1, 0), 0, {10, 10}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(domeMaster(Vec3::Zero(), Vec3(0, 1, 0), 361, {10, 10}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(domeMaster(Vec3::Zero(), Vec3(0, 1, 0), 180, {0, 10}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(domeMaster(Vec3(NAN, 0, 0), Vec3(0, 1, 0), 180, {10, 10}).error().code,
            ErrorCode::kInvalidInput);
}

TEST(DomeMaster, LookupOfAProjectorOnACeiling) {
  // A ceiling z = 2 (two triangles), a 320 x 200 projector at the origin looking
  // straight up, the eye 0.5 m beside it.
  geom::TriangleMesh ceiling;
  ceiling.vertices = {{-20, -20, 2}, {20, -20, 2}, {20, 20, 2}, {-20, 20, 2}};
  ceiling.faces = {{0, 1, 2}, {0, 2, 3}};
  auto surface = geom::MeshIntersector::build(ceiling);
  ASSERT_TRUE(surface);
  Mat34 P;  // K [I | 0], f = 200
  P << 200, 0, 159.5, 0, 0, 200, 99.5, 0, 0, 0, 1, 0;
  auto m = domeMaster(Vec3(0.5, 0, 0), Vec3(0, 1, 0), 180, {512, 512});
  ASSERT_TRUE(m);
  auto g = lookupGridForDome(*surface, P, {320, 200}, *m, 8);
  ASSERT_TRUE(g) << g.error().message;
  double worst = 0;
  int n = 0;
  for (int j = 0; j < g->rows; ++j) {
    for (int i = 0; i < g->cols; ++i) {
      const Vec2 u = g->node(i, j);
      const Vec3 X(2 * (u.x() - 159.5) / 200, 2 * (u.y() - 99.5) / 200, 2);
      const auto c = m->contentPixel(X);
      ASSERT_TRUE(c);
      worst = std::max(worst, (g->at(i, j) - *c).norm());
      ++n;
    }
  }
  EXPECT_EQ(n, g->rows * g->cols);
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(lookupGridForDome(*surface, P, {320, 200}, *m, 0).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::render
