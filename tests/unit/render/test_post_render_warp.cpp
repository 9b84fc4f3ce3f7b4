// The post-rendering warp ([Raskar02] §4.1.3): a projector with a lens, drawn through
// the pinhole of its K and pose, shows what its pixels lit once every framebuffer pixel
// samples the pinhole's image where the warp sends it. Ground truth: the lens model
// itself (the ideal pixel of every framebuffer pixel, geom::CameraModel::undistortPixel).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "render/post_render_warp.hpp"
#include "render/viewer_view.hpp"

namespace procam::render {
namespace {

// A 1280x800 projector 2 m from a wall (the plane z = 2), with a barrel lens of 3.4 px
// at the frame's corners.
geom::CameraModel lensProjector() {
  geom::CameraModel m;
  m.width = 1280;
  m.height = 800;
  m.K.fx = m.K.fy = 1372.0;
  m.K.cx = 639.5;
  m.K.cy = 399.5;
  m.dist.k1 = -0.015;
  m.dist.k2 = 0.004;
  m.dist.p1 = 0.0004;
  return m;
}

// What structured light measures: the wall point each node pixel (every `step` px) lit
// through the lens, meshed over the node grid in projector space.
geom::TriangleMesh measuredWall(const geom::CameraModel& m, int step) {
  geom::TriangleMesh mesh;
  const int cols = (m.width - 1) / step + 1, rows = (m.height - 1) / step + 1;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const Vec2 u(i * step, j * step);
      auto ray = m.backproject(u);
      EXPECT_TRUE(ray);
      const double t = (2.0 - ray->origin.z()) / ray->dir.z();
      mesh.vertices.push_back(ray->origin + t * ray->dir);
      mesh.uv.push_back(u);
    }
  }
  for (int j = 0; j + 1 < rows; ++j) {
    for (int i = 0; i + 1 < cols; ++i) {
      const int a = j * cols + i;
      mesh.faces.emplace_back(a, a + 1, a + cols + 1);
      mesh.faces.emplace_back(a, a + cols + 1, a + cols);
    }
  }
  return mesh;
}

TEST(PostRenderWarp, MeasuredWarpSendsEveryPixelToThePinholePixelOfWhatItLit) {
  const geom::CameraModel m = lensProjector();
  const geom::TriangleMesh wall = measuredWall(m, 16);
  auto warp = measuredPostRenderWarp(wall, m.projectionMatrix(), {m.width, m.height});
  ASSERT_TRUE(warp) << warp.error().message;
  EXPECT_EQ(warp->source, PostRenderWarp::Source::kMeasured);
  EXPECT_EQ(warp->points, static_cast<int>(wall.vertices.size()));
  // The lens moves the corners by about 3.4 px: the warp's extent says so.
  EXPECT_GT(warp->max_px, 3.0);
  EXPECT_LT(warp->max_px, 4.0);
  std::mt19937 rng(7);
  // Inside the measured nodes (the last at 1264, 784): the mesh, and so what is drawn,
  // ends there.
  std::uniform_real_distribution<double> x(0, 1264), y(0, 784);
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec2 u(x(rng), y(rng));
    const auto to = gridSource(warp->grid, u);
    ASSERT_TRUE(to);
    const auto ideal = m.undistortPixel(u);
    ASSERT_TRUE(ideal);
    worst = std::max(worst, (*to - *ideal).norm());
  }
  // Linear between 16 px measurements and 8 px nodes of a field whose curvature is
  // ~1e-5 px / px^2: a few hundredths of a pixel.
  std::printf(
      "[ figures  ] measured warp vs the lens: %.4f px at worst (moves %.3f px RMS, %.3f max)\n",
      worst, warp->rms_px, warp->max_px);
  EXPECT_LT(worst, 0.05);
}

TEST(PostRenderWarp, RaysThroughTheWarpMeetTheWallWhereTheLensSendsThem) {
  const geom::CameraModel m = lensProjector();
  const geom::TriangleMesh wall = measuredWall(m, 16);
  auto warp = projectorPostRenderWarp(m, &wall);
  ASSERT_TRUE(warp && *warp);
  auto plain = pixelRays(m.projectionMatrix());
  auto warped =
      pixelRays(m.projectionMatrix(), std::shared_ptr<const WarpGrid>(*warp, &(*warp)->grid));
  ASSERT_TRUE(plain && warped);
  double before = 0, after = 0;
  for (const Vec2& u :
       {Vec2(0, 0), Vec2(1264, 0), Vec2(1264, 784), Vec2(0, 784), Vec2(640, 10), Vec2(320, 600)}) {
    auto truth = m.backproject(u);
    ASSERT_TRUE(truth);
    auto onWall = [](const geom::Ray& r) {
      return r.origin + (2.0 - r.origin.z()) / r.dir.z() * r.dir;
    };
    const Vec3 X = onWall(*truth);
    before = std::max(before, (onWall(plain->through(u.x(), u.y())) - X).norm());
    after = std::max(after, (onWall(warped->through(u.x(), u.y())) - X).norm());
  }
  // 3.4 px of a 1372 px focal length at 2 m: about 5 mm; through the warp, under 0.1 mm.
  EXPECT_GT(before, 3e-3);
  EXPECT_LT(after, 1e-4);
}

TEST(PostRenderWarp, LensWarpIsTheIdealPixelAndNoneIsNeededWithoutALens) {
  geom::CameraModel m = lensProjector();
  auto lens = lensPostRenderWarp(m);
  ASSERT_TRUE(lens);
  EXPECT_EQ(lens->source, PostRenderWarp::Source::kLens);
  for (int j = 0; j < lens->grid.rows; j += 7) {
    for (int i = 0; i < lens->grid.cols; i += 7) {
      const auto ideal = m.undistortPixel(lens->grid.node(i, j));
      ASSERT_TRUE(ideal);
      EXPECT_LT((lens->grid.at(i, j) - *ideal).norm(), 1e-9);
    }
  }
  // The mesh's pixels win over the lens; with neither there is nothing to warp.
  geom::TriangleMesh bare = measuredWall(m, 32);
  bare.uv.clear();
  auto from_lens = projectorPostRenderWarp(m, &bare);
  ASSERT_TRUE(from_lens && *from_lens);
  EXPECT_EQ((*from_lens)->source, PostRenderWarp::Source::kLens);
  m.dist = {};
  auto none = projectorPostRenderWarp(m, &bare);
  ASSERT_TRUE(none);
  EXPECT_FALSE(*none);
}

TEST(PostRenderWarp, BadInputIsRefused) {
  const geom::CameraModel m = lensProjector();
  geom::TriangleMesh wall = measuredWall(m, 64);
  const Mat34 P = m.projectionMatrix();
  geom::TriangleMesh no_uv = wall;
  no_uv.uv.pop_back();
  EXPECT_EQ(measuredPostRenderWarp(no_uv, P, {1280, 800}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(measuredPostRenderWarp(wall, P, {1, 800}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(measuredPostRenderWarp(wall, P, {1280, 800}, 0).error().code, ErrorCode::kInvalidInput);
  Mat34 bad = P;
  bad(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(measuredPostRenderWarp(wall, bad, {1280, 800}).error().code, ErrorCode::kInvalidInput);
  // The wall behind the projector: nothing measured in front of it.
  geom::TriangleMesh behind = wall;
  for (auto& v : behind.vertices) v.z() = -v.z();
  EXPECT_EQ(measuredPostRenderWarp(behind, P, {1280, 800}).error().code, ErrorCode::kTooFewPoints);
  // A face out of range; u v that are not the projector's pixels (texture coordinates).
  geom::TriangleMesh bad_face = wall;
  bad_face.faces.emplace_back(0, 1, static_cast<int>(wall.vertices.size()));
  EXPECT_EQ(measuredPostRenderWarp(bad_face, P, {1280, 800}).error().code,
            ErrorCode::kInvalidInput);
  geom::TriangleMesh texture = wall;
  for (auto& t : texture.uv) t = Vec2(t.x() / 1279, t.y() / 799);
  EXPECT_EQ(measuredPostRenderWarp(texture, P, {1280, 800}).error().code, ErrorCode::kDegenerate);
  // A pixel far off the frame: refused, nothing cast out of range.
  geom::TriangleMesh far = wall;
  far.uv[0] = Vec2(-1e30, 1e30);
  EXPECT_FALSE(measuredPostRenderWarp(far, P, {1280, 800}).has_value());
  // No NaN or Inf leaves it.
  auto ok = measuredPostRenderWarp(wall, P, {1280, 800});
  ASSERT_TRUE(ok);
  for (const Vec2& s : ok->grid.source) EXPECT_TRUE(s.allFinite());
}

}  // namespace
}  // namespace procam::render
