// Placement of 3D content (content/mesh_placement.hpp): the documented rule on a wall
// lit by a straight projector, the Lambert shade of a face facing the viewer, and the
// planar 3D matrix showing points on the wall where the projector lights them.
#include <gtest/gtest.h>

#include <cmath>

#include "content/mesh_placement.hpp"

namespace procam::content {
namespace {

// A 2 x 1 x 0.5 box with its bounds at the origin, 12 triangles.
MeshContent box() {
  MeshContent c;
  for (int i = 0; i < 8; ++i) {
    c.mesh.vertices.emplace_back(i & 1 ? 2.0 : 0.0, i & 2 ? 1.0 : 0.0, i & 4 ? 0.5 : 0.0);
  }
  const int faces[12][3] = {{0, 3, 1}, {0, 2, 3}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                            {2, 7, 3}, {2, 6, 7}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  for (const auto& f : faces) c.mesh.faces.emplace_back(f[0], f[1], f[2]);
  c.min = Vec3::Zero();
  c.max = Vec3(2, 1, 0.5);
  return c;
}

// A 640x480 projector at (0, 0, 1.5) looking along +Y at the wall y = 3.
PlanarView wallView() {
  PlanarView v;
  Mat3 K;
  K << 800, 0, 319.5, 0, 800, 239.5, 0, 0, 1;
  Mat3 R;
  R << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // camera x = +X, y = -Z (down), z = +Y
  const Vec3 C(0, 0, 1.5);
  v.projector << K * R, K * (-R * C);
  v.size = {640, 480};
  v.plane_point = Vec3(0, 3, 0);
  v.plane_normal = Vec3(0, 1, 0);  // either orientation: it is turned toward the viewer
  v.eye = Vec3(0.4, 0.8, 1.7);
  return v;
}

TEST(MeshPlacement, BoxStandsOnTheWallCentredOnSAndShaded) {
  const PlanarView view = wallView();
  auto placed = placeMeshContent(box(), view);
  ASSERT_TRUE(placed) << placed.error().message;
  const keystone::DisplayRect& S = placed->S;
  // u = +X, v = +Z (world up), n = -Y toward the viewer; S bounds the image (pixel
  // edges) 3 m away: 640/800 * 3 = 2.4 m wide, 1.8 m high, centred on (0, 3, 1.5).
  EXPECT_NEAR(S.width, 640 / 800.0 * 3, 1e-9);
  EXPECT_NEAR(S.height, 480 / 800.0 * 3, 1e-9);
  Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
  for (const Vec3& p : placed->mesh.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // Larger x-y extent (x: 2) -> half of S's smaller side (0.9 m): scale 0.45.
  const double scale = 0.5 * S.height / 2;
  EXPECT_NEAR(hi.x() - lo.x(), 2 * scale, 1e-9);
  EXPECT_NEAR(hi.z() - lo.z(), 1 * scale, 1e-9);
  EXPECT_NEAR(0.5 * (hi.x() + lo.x()), 0, 1e-9);
  EXPECT_NEAR(0.5 * (hi.z() + lo.z()), 1.5, 1e-9);
  // The back on the wall, the front 0.5 * scale toward the viewer (under a quarter of
  // the viewer's 2.2 m distance, so not limited by it).
  EXPECT_NEAR(hi.y(), 3, 1e-12);
  EXPECT_NEAR(hi.y() - lo.y(), 0.5 * scale, 1e-9);
  ASSERT_EQ(placed->mesh.triangles.size(), 12u);
  ASSERT_EQ(placed->mesh.colors.size(), 36u);
  // The front face (normal -Y = n): kMeshAmbient + (1 - kMeshAmbient) * 0.8 / |l|.
  const double facing = 0.8 / std::sqrt(0.3 * 0.3 + 0.5 * 0.5 + 0.8 * 0.8);
  const int front_grey = static_cast<int>(std::lround(255 * (0.25 + 0.75 * facing)));
  int front = 0;
  for (size_t t = 0; t < 12; ++t) {
    const Vec3& a = placed->mesh.vertices[3 * t];
    if (std::abs(a.y() - lo.y()) < 1e-12 &&
        std::abs(placed->mesh.vertices[3 * t + 1].y() - lo.y()) < 1e-12 &&
        std::abs(placed->mesh.vertices[3 * t + 2].y() - lo.y()) < 1e-12) {
      ++front;
      EXPECT_EQ(placed->mesh.colors[3 * t], cv::Vec4b(front_grey, front_grey, front_grey, 255));
    }
  }
  EXPECT_EQ(front, 2);
  // Points on the wall appear where the projector lights them ([Raskar02] §4.2.1: the
  // viewer's ray meets the wall at the point itself).
  for (const Vec3& p : placed->mesh.vertices) {
    if (std::abs(p.y() - 3) > 1e-12) continue;
    const Vec4 c = placed->planar3d * p.homogeneous();
    ASSERT_GT(c.w(), 0);
    EXPECT_LE(std::abs(c.z()), c.w());
    const Vec2 px = c.head<2>() / c.w();
    const Vec2 truth = (view.projector * p.homogeneous()).hnormalized();
    EXPECT_LT((px - truth).norm(), 1e-6);
  }
}

// The view-dependent part for a moved viewer: a point of the placed mesh (off the wall)
// lands on the projector pixel that lights the wall where the new viewer's ray through
// it meets the wall ([Raskar02] §4.2.1), inside the depth range; a viewer behind the wall is
// refused.
TEST(MeshPlacement, Planar3dForAMovedViewerFollowsTheirRays) {
  PlanarView view = wallView();
  auto placed = placeMeshContent(box(), view);
  ASSERT_TRUE(placed) << placed.error().message;
  view.eye = Vec3(-0.6, 1.2, 1.3);
  auto m = planar3dForViewer(view, placed->S);
  ASSERT_TRUE(m) << m.error().message;
  for (const Vec3& p : placed->mesh.vertices) {
    const Vec4 c = *m * p.homogeneous();
    ASSERT_GT(c.w(), 0);
    EXPECT_LE(std::abs(c.z()), c.w());
    const Vec3 d = p - view.eye;
    const Vec3 wall = view.eye + ((3 - view.eye.y()) / d.y()) * d;  // the wall y = 3
    const Vec2 truth = (view.projector * wall.homogeneous()).hnormalized();
    EXPECT_LT((c.head<2>() / c.w() - truth).norm(), 1e-6);
  }
  view.eye = Vec3(0, 3.5, 1.5);
  auto behind = planar3dForViewer(view, placed->S);
  ASSERT_FALSE(behind);
  EXPECT_EQ(behind.error().code, ErrorCode::kDegenerate);
}

TEST(MeshPlacement, ViewerOnThePlaneIsDegenerate) {
  PlanarView view = wallView();
  view.eye = Vec3(0.5, 3.0, 1.5);
  auto placed = placeMeshContent(box(), view);
  ASSERT_FALSE(placed);
  EXPECT_EQ(placed.error().code, ErrorCode::kDegenerate);
}

}  // namespace
}  // namespace procam::content
