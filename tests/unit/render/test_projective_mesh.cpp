// Two-pass projective texture map against ray casting in double.
#include <gtest/gtest.h>

#include "render/projective_mesh.hpp"
#include "render_test_rig.hpp"

namespace procam::render {
namespace {

// Compares the map with ray casting at every `stride`-th pixel; every pixel must agree
// on coverage, and covered pixels within float rounding of coordinates < 2048 plus the
// double error of the ray cast (1e-3 px is ~8 float ulps).
void expectMatchesRayCast(const SurfaceMesh& mesh, const Mat34& P, const Mat34& V, cv::Size size,
                          int stride) {
  auto map = projectiveTextureMap(mesh, P, V, size);
  ASSERT_TRUE(map);
  int covered = 0;
  for (int y = 0; y < size.height; y += stride) {
    for (int x = 0; x < size.width; x += stride) {
      Vec3 o, d;
      test::pixelRay(P, x, y, o, d);
      const auto hit = test::intersect(mesh, o, d);
      const cv::Vec2f m = map->xy.at<cv::Vec2f>(y, x);
      ASSERT_EQ(hit.has_value(), m[0] != kOutside) << x << "," << y;
      if (!hit) continue;
      const Vec2 e = (V * hit->homogeneous()).hnormalized();
      EXPECT_NEAR(m[0], e.x(), 1e-3) << x << "," << y;
      EXPECT_NEAR(m[1], e.y(), 1e-3) << x << "," << y;
      ++covered;
    }
  }
  EXPECT_GT(covered, 0);
}

TEST(ProjectiveTexture, ObliquePlaneMatchesRayCasting) {
  // Wall y = 3 (world +Z up), projector low and to the left, viewer elsewhere.
  const SurfaceMesh wall =
      test::planeMesh(Vec3(0, 3, 1.2), Vec3::UnitX(), Vec3::UnitZ(), 2.0, 1.5, 3);
  const Mat34 P = test::lookAtProjection(700, 319.5, 239.5, Vec3(-0.6, 0, 0.7), Vec3(0.1, 3, 1.3),
                                         Vec3::UnitZ());
  const Mat34 V = test::lookAtProjection(900, 511.5, 383.5, Vec3(0.4, 0.5, 1.6), Vec3(0, 3, 1.2),
                                         Vec3::UnitZ());
  expectMatchesRayCast(wall, P, V, {640, 480}, 7);
}

TEST(ProjectiveTexture, NearerSurfaceWinsTheDepthTest) {
  SurfaceMesh two = test::planeMesh(Vec3(0, 3, 1.2), Vec3::UnitX(), Vec3::UnitZ(), 2.0, 1.5, 1);
  const SurfaceMesh front =
      test::planeMesh(Vec3(0.2, 2, 1.2), Vec3::UnitX(), Vec3::UnitZ(), 0.3, 0.3, 1);
  // Front panel listed after and before the wall: the result must not depend on order.
  const int base = static_cast<int>(two.vertices.size());
  two.vertices.insert(two.vertices.end(), front.vertices.begin(), front.vertices.end());
  for (auto t : front.triangles) two.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  const Mat34 P =
      test::lookAtProjection(600, 159.5, 119.5, Vec3(0, 0, 1.2), Vec3(0, 3, 1.2), Vec3::UnitZ());
  const Mat34 V = test::lookAtProjection(500, 159.5, 119.5, Vec3(-0.5, 0.3, 1.0), Vec3(0, 3, 1.2),
                                         Vec3::UnitZ());
  expectMatchesRayCast(two, P, V, {320, 240}, 3);
  SurfaceMesh reversed = two;
  std::reverse(reversed.triangles.begin(), reversed.triangles.end());
  auto a = projectiveTextureMap(two, P, V, {320, 240});
  auto b = projectiveTextureMap(reversed, P, V, {320, 240});
  ASSERT_TRUE(a && b);
  EXPECT_EQ(cv::norm(a->xy, b->xy, cv::NORM_INF), 0.0);
}

TEST(ProjectiveTexture, DomeSeenFromInsideMatchesRayCasting) {
  const SurfaceMesh dome = test::domeMesh(Vec3(0, 0, 0), 2.0, 12, 32);
  const Mat34 P = test::lookAtProjection(300, 199.5, 149.5, Vec3(0.3, 0.2, 0.1), Vec3(0.3, 2, 0.4),
                                         Vec3::UnitZ());
  const Mat34 V = test::lookAtProjection(350, 199.5, 149.5, Vec3(-0.2, 0.1, -0.3), Vec3(0, 2, 0),
                                         Vec3::UnitZ());
  expectMatchesRayCast(dome, P, V, {400, 300}, 5);
}

TEST(ProjectiveTexture, BadIndicesAndDepthRangeErrors) {
  SurfaceMesh m;
  m.vertices = {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1)};
  m.triangles = {{0, 1, 3}};
  const Mat34 P = test::lookAtProjection(100, 50, 50, Vec3::Zero(), Vec3(0, 0, 1), Vec3::UnitY());
  EXPECT_EQ(projectiveTextureMap(m, P, P, {10, 10}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(pixelProjectionWithDepth(P, 2, 1).error().code, ErrorCode::kInvalidInput);
  auto M = pixelProjectionWithDepth(P, 0.5, 4.0);
  ASSERT_TRUE(M);
  const Vec4 near = *M * Vec4(0, 0, 0.5, 1), far = *M * Vec4(0, 0, 4.0, 1);
  EXPECT_NEAR(near.z() / near.w(), -1, 1e-12);
  EXPECT_NEAR(far.z() / far.w(), 1, 1e-12);
}

}  // namespace
}  // namespace procam::render
