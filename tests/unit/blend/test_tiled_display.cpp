// The display rectangle across several projectors on a planar wall.
#include <gtest/gtest.h>

#include <cmath>

#include "blend/feather.hpp"
#include "blend/tiled_display.hpp"
#include "keystone/rig_keystone.hpp"
#include "wall_tiles.hpp"

namespace procam::blend {
namespace {

using testing::twoByTwo;
using testing::wallProjector;

bool covered(const TiledDisplay& d, const Vec2& p) {
  for (const auto& q : d.footprints)
    if (insideDistance(q, p) > 0) return true;
  return false;
}

// Every point of a 100 x 100 lattice over the rectangle lies in some projector's image.
void expectInsideTheUnion(const TiledDisplay& d) {
  const auto& r = d.rect;
  int outside = 0;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 100; ++j)
      outside += !covered(d, r.centre + Vec2((j / 50.0 - 1) * r.half_width * (1 - 1e-9),
                                             (i / 50.0 - 1) * r.half_height * (1 - 1e-9)));
  EXPECT_EQ(outside, 0);
}

// One projector: the same rectangle as the exact linear program of the single
// keystone, to the raster's accuracy (a fine cell per side: area within
// 4 cell / size, here 0.5 %).
TEST(TiledDisplay, OneTileMatchesTheKeystoneRectangle) {
  const auto p = wallProjector({0.3, 0.5, 1.2}, -25, 12);
  auto d = solveTiledDisplay(std::vector<DisplayTile>{p.tile}, 1920, 1080);
  ASSERT_TRUE(d) << d.error().message;
  keystone::RigKeystoneProblem one;
  one.projector_to_plane = p.tile.projector_to_plane;
  one.width = p.tile.width;
  one.height = p.tile.height;
  one.content_width = 1920;
  one.content_height = 1080;
  auto exact = keystone::solveRigKeystone(one);
  ASSERT_TRUE(exact) << exact.error().message;
  const double ratio = d->rect.area() / exact->rect.area();
  std::printf("[ figures  ] one tile: area %.5f of the exact rectangle, cell %.2f mm\n", ratio,
              1000 * d->cell_m);
  EXPECT_LE(ratio, 1.0 + 1e-9);
  EXPECT_GE(ratio, 1.0 - 4 * d->cell_m / (2 * exact->rect.half_height));
  EXPECT_NEAR(d->rect.half_width / d->rect.half_height, 1920.0 / 1080, 1e-12);
  expectInsideTheUnion(*d);
}

// Four projectors: the rectangle is upright by construction, of the content's aspect,
// inside the union, larger than any one image can hold, and each tile's homography
// takes the content's corners to the rectangle's corners on the wall.
TEST(TiledDisplay, TwoByTwoWallIsOneRectangle) {
  const auto ps = twoByTwo();
  const auto tiles = testing::tilesOf(ps);
  auto d = solveTiledDisplay(tiles, 1920, 1080);
  ASSERT_TRUE(d) << d.error().message;
  expectInsideTheUnion(*d);
  double largest_single = 0;
  for (const auto& t : tiles) {
    auto one = solveTiledDisplay(std::vector<DisplayTile>{t}, 1920, 1080);
    ASSERT_TRUE(one);
    largest_single = std::max(largest_single, one->rect.area());
  }
  std::printf(
      "[ figures  ] 2x2: display %.3f x %.3f m, %.1f %% of the union (%.3f m2), %.2fx one "
      "image's rectangle\n",
      2 * d->rect.half_width, 2 * d->rect.half_height, 100 * d->rect.area() / d->union_area_m2,
      d->union_area_m2, d->rect.area() / largest_single);
  EXPECT_GT(d->rect.area(), 2.5 * largest_single);
  // A finer raster finds no rectangle larger by more than a cell per side.
  auto finer = solveTiledDisplay(
      tiles, 1920, 1080, {.raster_cells = 2048, .rect = std::nullopt, .world_rect = std::nullopt});
  ASSERT_TRUE(finer);
  EXPECT_LT(finer->rect.area() / d->rect.area(), 1 + 4 * d->cell_m / (2 * d->rect.half_height));
  // Content corners -> framebuffer -> wall: the rectangle's corners.
  const Mat3 c2w = contentToWall(d->rect, 1920, 1080);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const Mat3 back = d->plane_to_framebuffer[t].inverse() * d->content_to_framebuffer[t];
    for (const Vec2& c : {Vec2(-0.5, -0.5), Vec2(1919.5, -0.5), Vec2(1919.5, 1079.5)}) {
      const Vec2 a = (back * c.homogeneous()).hnormalized();
      const Vec2 b = (c2w * c.homogeneous()).hnormalized();
      EXPECT_LT((a - b).norm(), 1e-9) << "tile " << t;
    }
  }
  // Upright: content's top edge runs along the wall's horizontal.
  const Vec2 tl = (c2w * Vec3(-0.5, -0.5, 1)).hnormalized();
  const Vec2 tr = (c2w * Vec3(1919.5, -0.5, 1)).hnormalized();
  EXPECT_NEAR(tl.y(), tr.y(), 1e-12);
  EXPECT_GT(tr.x(), tl.x());
  EXPECT_GT(tl.y(), d->rect.centre.y());  // the content's top is up on the wall
}

TEST(TiledDisplay, GivenRectangleIsUsedWhenInside) {
  const auto tiles = testing::tilesOf(twoByTwo());
  keystone::AxisRect r;
  r.centre = Vec2(0.1, 0.0);
  r.half_width = 0.8;
  r.half_height = 0.45;
  auto d = solveTiledDisplay(tiles, 1600, 900,
                             {.raster_cells = 512, .rect = r, .world_rect = std::nullopt});
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_NEAR(d->rect.half_width, 0.8, 1e-12);
  r.half_width = 5;
  r.half_height = 5 * 9.0 / 16;
  auto outside = solveTiledDisplay(tiles, 1600, 900,
                                   {.raster_cells = 512, .rect = r, .world_rect = std::nullopt});
  ASSERT_FALSE(outside);
  EXPECT_EQ(outside.error().code, ErrorCode::kInvalidInput);
}

// The same rectangle given in world coordinates: its centre a wall point, its size in
// metres; off the wall plane, or together with a basis rectangle, it is refused.
TEST(TiledDisplay, GivenWorldRectangleIsTheSameRectangle) {
  const auto tiles = testing::tilesOf(twoByTwo());
  auto largest = solveTiledDisplay(tiles, 1600, 900);
  ASSERT_TRUE(largest) << largest.error().message;
  const geom::PlaneBasis& b = largest->basis;
  const Vec2 centre(0.1, 0.0);
  WorldRect w{b.toWorld(centre), 1.6, 0.9};
  auto d = solveTiledDisplay(tiles, 1600, 900,
                             {.raster_cells = 512, .rect = std::nullopt, .world_rect = w});
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_NEAR((d->rect.centre - centre).norm(), 0, 1e-12);
  EXPECT_NEAR(d->rect.half_width, 0.8, 1e-12);
  EXPECT_NEAR(d->rect.half_height, 0.45, 1e-12);
  w.centre += 0.02 * b.normal();  // 2 cm in front of the wall
  auto off = solveTiledDisplay(tiles, 1600, 900,
                               {.raster_cells = 512, .rect = std::nullopt, .world_rect = w});
  ASSERT_FALSE(off);
  EXPECT_EQ(off.error().code, ErrorCode::kInvalidInput);
  auto twice = solveTiledDisplay(
      tiles, 1600, 900,
      {.raster_cells = 512, .rect = keystone::AxisRect{centre, 0.8, 0.45}, .world_rect = w});
  EXPECT_FALSE(twice);
}

TEST(TiledDisplay, BadTilesAreRefused) {
  auto tiles = testing::tilesOf(twoByTwo());
  EXPECT_EQ(solveTiledDisplay(std::vector<DisplayTile>{}, 10, 10).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(solveTiledDisplay(tiles, 0, 10).error().code, ErrorCode::kInvalidInput);
  auto other_plane = tiles;
  other_plane[2].projector_to_plane.basis.origin += Vec3(0, 0.01, 0);  // 1 cm off the wall
  EXPECT_EQ(solveTiledDisplay(other_plane, 10, 10).error().code, ErrorCode::kInvalidInput);
  auto singular = tiles;
  singular[1].projector_to_plane.H = Mat3::Zero();
  EXPECT_EQ(solveTiledDisplay(singular, 10, 10).error().code, ErrorCode::kInvalidInput);
  auto nan = tiles;
  nan[0].projector_to_plane.H(0, 0) = std::nan("");
  EXPECT_FALSE(solveTiledDisplay(nan, 10, 10));
}

}  // namespace
}  // namespace procam::blend
