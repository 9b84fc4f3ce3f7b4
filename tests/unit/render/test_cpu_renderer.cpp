// Render-path choice and the CPU renderer's behaviour as one interface.
#include <gtest/gtest.h>

#include <atomic>

#include "render/bilinear.hpp"
#include "render/cpu_renderer.hpp"
#include "render/raster_triangles.hpp"
#include "render/render_path.hpp"
#include "render_test_images.hpp"
#include "render_test_rig.hpp"

namespace procam::render {
namespace {

TEST(RenderPath, FollowsTheDesignTable) {
  auto pick = [](SurfaceKind s, ViewerKind v, ContentKind c, int n) {
    return *choosePath(SceneTraits{s, v, c, n});
  };
  EXPECT_EQ(pick(SurfaceKind::kPlanar, ViewerKind::kUntracked, ContentKind::kImage, 1).path,
            RenderPath::kHomography);
  EXPECT_EQ(pick(SurfaceKind::kPlanar, ViewerKind::kTracked, ContentKind::kImage, 1).path,
            RenderPath::kHomography);
  EXPECT_EQ(pick(SurfaceKind::kPlanar, ViewerKind::kTracked, ContentKind::kMesh3d, 1).path,
            RenderPath::kPlanar3d);
  EXPECT_EQ(pick(SurfaceKind::kPlanar, ViewerKind::kStatic, ContentKind::kMesh3d, 1).path,
            RenderPath::kPlanar3d);
  const auto tiled = pick(SurfaceKind::kPlanar, ViewerKind::kUntracked, ContentKind::kImage, 3);
  EXPECT_EQ(tiled.path, RenderPath::kHomography);
  EXPECT_TRUE(tiled.blend);
  EXPECT_FALSE(tiled.post_warp);
  const auto dome = pick(SurfaceKind::kNonPlanar, ViewerKind::kTracked, ContentKind::kImage, 3);
  EXPECT_EQ(dome.path, RenderPath::kTwoPassMesh);
  EXPECT_TRUE(dome.post_warp && dome.blend);
  EXPECT_EQ(pick(SurfaceKind::kNonPlanar, ViewerKind::kStatic, ContentKind::kImage, 1).path,
            RenderPath::kLookupWarp);
  EXPECT_FALSE(
      pick(SurfaceKind::kNonPlanar, ViewerKind::kTracked, ContentKind::kImage, 1).post_warp);
  // An object is painted from each projector with its own weights: no post warp.
  const auto lamps = pick(SurfaceKind::kObject, ViewerKind::kTracked, ContentKind::kMesh3d, 3);
  EXPECT_EQ(lamps.path, RenderPath::kShaderLamps);
  EXPECT_TRUE(lamps.blend);
  EXPECT_FALSE(lamps.post_warp);
  EXPECT_EQ(pick(SurfaceKind::kObject, ViewerKind::kUntracked, ContentKind::kImage, 1).path,
            RenderPath::kShaderLamps);
  EXPECT_STREQ(toString(RenderPath::kShaderLamps), "shader-lamps");
  // No renderer is configured for it: its frames come drawn.
  RenderSetup drawn;
  drawn.output_size = {8, 8};
  drawn.content_size = {8, 8};
  drawn.path = RenderPath::kShaderLamps;
  EXPECT_EQ(CpuRenderer().configure(drawn).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(
      choosePath({SurfaceKind::kPlanar, ViewerKind::kTracked, ContentKind::kImage, 0}).error().code,
      ErrorCode::kInvalidInput);
}

TEST(CpuRenderer, UnchangedFrameIsNotRenderedAgain) {
  CpuRenderer r;
  RenderSetup s;
  s.output_size = {64, 48};
  s.content_size = {32, 24};
  s.homography << 2, 0, 0.5, 0, 2, 0.5, 0, 0, 1;
  ASSERT_TRUE(r.configure(s));
  cv::Mat content = test::randomImage(s.content_size, 1);
  EXPECT_TRUE(*r.render({&content, nullptr, 1}));
  cv::Mat first;
  ASSERT_TRUE(r.readFrame(first));
  content.setTo(cv::Scalar::all(9));  // changed pixels, same version: not re-rendered
  EXPECT_FALSE(*r.render({&content, nullptr, 1}));
  cv::Mat second;
  ASSERT_TRUE(r.readFrame(second));
  EXPECT_EQ(cv::norm(first, second, cv::NORM_INF), 0.0);
  EXPECT_TRUE(*r.render({&content, nullptr, 2}));
  EXPECT_FALSE(*r.render({&content, nullptr, 2}));
  ASSERT_TRUE(r.configure(s));  // geometry change forces a frame
  EXPECT_TRUE(*r.render({&content, nullptr, 2}));
}

TEST(CpuRenderer, HomographyFrameMatchesTheSpecification) {
  CpuRenderer r;
  RenderSetup s;
  s.output_size = {160, 120};
  s.content_size = {100, 80};
  s.homography << 1.2, 0.1, 10, -0.05, 1.1, 5, 4e-4, 2e-4, 1;
  ASSERT_TRUE(r.configure(s));
  const cv::Mat content = test::smoothImage(s.content_size, 0.05, 0.04);
  ASSERT_TRUE(r.render({&content, nullptr, 1}));
  cv::Mat frame;
  ASSERT_TRUE(r.readFrame(frame));
  const Mat3 Hinv = s.homography.inverse();
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const Vec2 p = (Hinv * Vec3(x, y, 1)).hnormalized();
      const cv::Vec4d e = sampleBilinear(content, p.x(), p.y());
      // Smooth content (G <= 6.4 per axis): <= 0.5 + 2 * 6.4 / 256 + float map error.
      for (int c = 0; c < 4; ++c) ASSERT_NEAR(frame.at<cv::Vec4b>(y, x)[c], e[c], 0.56);
    }
  }
}

TEST(CpuRenderer, PlanarMeshTwoPassEqualsTheInducedHomography) {
  // A planar surface rendered by the two-pass path must give the homography path's image:
  // the path choice changes cost, never the picture.
  const SurfaceMesh wall = test::planeMesh(Vec3(0, 3, 1.2), Vec3::UnitX(), Vec3::UnitZ(), 3, 2, 2);
  const Mat34 P =
      test::lookAtProjection(300, 159.5, 119.5, Vec3(-0.4, 0, 1.0), Vec3(0, 3, 1.3), Vec3::UnitZ());
  const Mat34 V =
      test::lookAtProjection(250, 99.5, 79.5, Vec3(0.3, 0.2, 1.4), Vec3(0, 3, 1.2), Vec3::UnitZ());
  RenderSetup mesh;
  mesh.output_size = {320, 240};
  mesh.content_size = {200, 160};
  mesh.path = RenderPath::kTwoPassMesh;
  mesh.surface = wall;
  mesh.projector = P;
  mesh.viewer = V;
  // Plane y = 3 in world: points (X, 3, Z) -> columns (0, 2, 3) plus 3 * column 1.
  auto plane = [](const Mat34& M) {
    Mat3 H;
    H.col(0) = M.col(0);
    H.col(1) = M.col(2);
    H.col(2) = M.col(3) + 3 * M.col(1);
    return H;
  };
  RenderSetup hom = mesh;
  hom.path = RenderPath::kHomography;
  hom.homography = plane(P) * plane(V).inverse();
  CpuRenderer a, b;
  ASSERT_TRUE(a.configure(mesh));
  ASSERT_TRUE(b.configure(hom));
  const cv::Mat content = test::detailedImage(mesh.content_size, 4);
  ASSERT_TRUE(a.render({&content, nullptr, 1}));
  ASSERT_TRUE(b.render({&content, nullptr, 1}));
  cv::Mat fa, fb;
  ASSERT_TRUE(a.readFrame(fa));
  ASSERT_TRUE(b.readFrame(fb));
  // Both maps are the same double mapping rounded to float, then quantised identically.
  EXPECT_LE(cv::norm(fa, fb, cv::NORM_INF), 1.0);
  EXPECT_GT(cv::countNonZero(fa.reshape(1) > 0), 1000);
}

TEST(CpuRenderer, PlanarPath3dTakesMeshesAndBadSetupsAreRejected) {
  CpuRenderer r;
  RenderSetup s;
  s.output_size = {8, 8};
  s.path = RenderPath::kPlanar3d;
  ASSERT_TRUE(r.configure(s));
  EXPECT_EQ(r.render({nullptr, nullptr, 1}).error().code, ErrorCode::kInvalidInput);
  ColoredMesh bad;
  bad.vertices = {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};
  bad.triangles = {{0, 1, 2}};
  EXPECT_EQ(r.render({nullptr, &bad, 1}).error().code, ErrorCode::kInvalidInput);  // no colours
  bad.colors.assign(3, cv::Vec4b(1, 2, 3, 4));
  bad.triangles = {{0, 1, 3}};
  EXPECT_EQ(r.render({nullptr, &bad, 1}).error().code, ErrorCode::kInvalidInput);  // index
  s.path = RenderPath::kTwoPassMesh;
  s.content_size = {8, 8};
  EXPECT_EQ(r.configure(s).error().code, ErrorCode::kInvalidInput);
  cv::Mat img(8, 8, CV_8UC4);
  EXPECT_EQ(r.render({&img, nullptr, 1}).error().code, ErrorCode::kInvalidInput);
}

// A stop that answers true ends a mesh frame with kCancelled; the next render draws the
// frame in full although the content version did not change, and a stop that never
// answers true leaves the frame as drawn without one.
TEST(CpuRenderer, AStoppedMeshFrameIsDrawnInFullNextTime) {
  RenderSetup s;
  s.output_size = {64, 48};
  s.path = RenderPath::kPlanar3d;
  s.planar3d = Mat4::Identity();  // pixel coordinates at depth 0, w = 1
  ColoredMesh mesh;
  for (int i = 0; i < 30000; ++i) {  // enough triangles for several stop checks
    const double x = i % 60, y = (i / 60) % 44;
    const int v = int(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(),
                         {Vec3(x, y, 0), Vec3(x + 3, y, 0), Vec3(x, y + 3, 0)});
    mesh.colors.insert(mesh.colors.end(), 3, cv::Vec4b(uint8_t(i % 251), 40, 200, 255));
    mesh.triangles.push_back({v, v + 1, v + 2});
  }
  CpuRenderer plain;
  ASSERT_TRUE(plain.configure(s));
  ASSERT_TRUE(*plain.render({nullptr, &mesh, 1}));

  CpuRenderer r;
  ASSERT_TRUE(r.configure(s));
  std::atomic<int> asked{0};
  auto stopped = r.render({nullptr, &mesh, 1, [&] { return ++asked >= 3; }});
  ASSERT_FALSE(stopped);
  EXPECT_EQ(stopped.error().code, ErrorCode::kCancelled);
  EXPECT_GE(asked.load(), 3);
  auto again = r.render({nullptr, &mesh, 1});  // same version: drawn all the same
  ASSERT_TRUE(again);
  EXPECT_TRUE(*again);
  EXPECT_EQ(cv::norm(r.frame(), plain.frame(), cv::NORM_INF), 0.0);

  CpuRenderer never;
  ASSERT_TRUE(never.configure(s));
  asked = 0;
  ASSERT_TRUE(*never.render({nullptr, &mesh, 1, [&] { return ++asked < 0; }}));
  EXPECT_GE(asked.load(), int(mesh.triangles.size() / kStopCheckTriangles));
  EXPECT_EQ(cv::norm(never.frame(), plain.frame(), cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace procam::render
