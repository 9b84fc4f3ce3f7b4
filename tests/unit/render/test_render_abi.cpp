// The output ABI's render setup and content: what the daemon hands over is what an
// output receives, and what a hostile or broken caller hands over is refused with a
// typed error, never read past its bounds.
#include <gtest/gtest.h>

#include "support/render_abi.hpp"

namespace procam::plugins {
namespace {

render::RenderSetup twoPassSetup() {
  render::RenderSetup s;
  s.output_size = {64, 48};
  s.content_size = {32, 24};
  s.path = render::RenderPath::kTwoPassMesh;
  s.surface.vertices = {Vec3(0, 0, 2), Vec3(1, 0, 2), Vec3(0, 1, 2.5)};
  s.surface.triangles = {{0, 1, 2}};
  s.projector << 50, 0, 32, 0, 0, 50, 24, 0, 0, 0, 1, 0;
  s.viewer << 30, 0.5, 16, 0.1, 0, 30, 12, 0.2, 0, 0, 1, 0.05;
  render::WarpGrid g;
  g.cols = 3;
  g.rows = 2;
  g.origin = Vec2(0.5, 0.25);
  g.step = Vec2(31, 47);
  g.source = {Vec2(1, 2), Vec2(3, 4), Vec2(5, 6), Vec2(7, 8), Vec2(9, 10), Vec2(11, 12)};
  s.post_warp = g;
  s.final_stage.alpha = cv::Mat(48, 64, CV_8UC1, cv::Scalar(200));
  s.final_stage.weight_lut[10] = 77;
  s.final_stage.output_lut[2][5] = 9;
  return s;
}

TEST(RenderAbi, SetupsSurviveTheBoundaryUnchanged) {
  for (render::RenderPath path :
       {render::RenderPath::kHomography, render::RenderPath::kPlanar3d,
        render::RenderPath::kTwoPassMesh, render::RenderPath::kLookupWarp}) {
    render::RenderSetup s = twoPassSetup();
    s.path = path;
    s.homography << 1.5, 0.1, 3, -0.2, 0.9, 4, 1e-4, 2e-4, 1;
    s.planar3d = Mat4::Identity() * 0.5;
    s.lookup = *s.post_warp;
    if (path == render::RenderPath::kPlanar3d) s.content_size = {};
    const RenderSetupView view(s);
    auto back = setupFromAbi(view.get());
    ASSERT_TRUE(back) << render::toString(path) << ": " << back.error().message;
    // Fields a path does not use are not carried: compare what the path reads.
    render::RenderSetup expected = s;
    if (path != render::RenderPath::kHomography) expected.homography = back->homography;
    if (path != render::RenderPath::kPlanar3d) expected.planar3d = back->planar3d;
    if (path != render::RenderPath::kTwoPassMesh) {
      expected.surface = back->surface;
      expected.projector = back->projector;
      expected.viewer = back->viewer;
    }
    if (path != render::RenderPath::kLookupWarp) expected.lookup = back->lookup;
    EXPECT_TRUE(render::sameSetup(*back, expected)) << render::toString(path);
  }
  // Shader-lamps frames come drawn: a setup that names the path does not cross as another.
  render::RenderSetup lamps = twoPassSetup();
  lamps.path = render::RenderPath::kShaderLamps;
  const RenderSetupView view(lamps);
  auto back = setupFromAbi(view.get());
  ASSERT_FALSE(back);
  EXPECT_EQ(back.error().code, ErrorCode::kInvalidInput);
}

TEST(RenderAbi, BrokenSetupsAreRefused) {
  const render::RenderSetup good = twoPassSetup();
  auto refused = [&](auto&& mutate) {
    const RenderSetupView view(good);
    procam_render_setup s = view.get();
    std::vector<int32_t> bad_indices = {0, 1, 3};
    std::vector<double> nan_vertices = {0, 0, 2, 1, 0, std::nan(""), 0, 1, 2};
    mutate(s, bad_indices, nan_vertices);
    auto r = setupFromAbi(s);
    return !r && r.error().code == ErrorCode::kInvalidInput;
  };
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.output_width = 0; }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.output_height = 1u << 20; }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) {
    const uint32_t path = 99;
    std::memcpy(&s.path, &path, sizeof path);
  }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto& idx, auto&) {
    s.surface_triangles = idx.data();  // index 3 of 3 vertices
  }));
  EXPECT_TRUE(
      refused([](procam_render_setup& s, auto&, auto& v) { s.surface_vertices = v.data(); }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.surface_vertices = nullptr; }));
  EXPECT_TRUE(
      refused([](procam_render_setup& s, auto&, auto&) { s.n_surface_vertices = 1ull << 40; }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.post_warp.rows = 1; }));
  // Finer than one node per output pixel (64 wide): refused before anything is read.
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.post_warp.cols = 66; }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.post_warp.step[0] = 0; }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.alpha_stride = 10; }));
  EXPECT_TRUE(refused([](procam_render_setup& s, auto&, auto&) { s.projector[3] = INFINITY; }));
}

TEST(RenderAbi, ContentIsCheckedAgainstTheSetupAndMeshesCachedByVersion) {
  render::RenderSetup s;
  s.output_size = {8, 8};
  s.content_size = {4, 4};
  const cv::Mat rgba(4, 4, CV_8UC4, cv::Scalar(1, 2, 3, 4));
  cv::Mat header;
  MeshCache cache;
  {
    const ContentView view(&rgba, nullptr, 7);
    auto c = contentFromAbi(view.get(), s, header, cache);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->image->data, rgba.data);  // no copy
    EXPECT_EQ(c->version, 7u);
  }
  const cv::Mat wrong(5, 4, CV_8UC4);
  const ContentView wrong_view(&wrong, nullptr, 8);
  EXPECT_FALSE(contentFromAbi(wrong_view.get(), s, header, cache));

  s.path = render::RenderPath::kPlanar3d;
  render::ColoredMesh mesh;
  mesh.vertices = {Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1)};
  mesh.colors.assign(3, cv::Vec4b(9, 8, 7, 255));
  mesh.triangles = {{0, 1, 2}};
  const ContentView mesh_view(nullptr, &mesh, 3);
  auto c = contentFromAbi(mesh_view.get(), s, header, cache);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->mesh->vertices, mesh.vertices);
  EXPECT_EQ(c->mesh->colors[2], cv::Vec4b(9, 8, 7, 255));
  // The same version is not read again: a changed mesh under it is not seen.
  mesh.vertices[0] = Vec3(5, 5, 5);
  const ContentView same_version(nullptr, &mesh, 3);
  ASSERT_TRUE(contentFromAbi(same_version.get(), s, header, cache));
  EXPECT_EQ(cache.mesh.vertices[0], Vec3(0, 0, 1));
  mesh.triangles = {{0, 1, 5}};
  const ContentView bad(nullptr, &mesh, 4);
  EXPECT_FALSE(contentFromAbi(bad.get(), s, header, cache));
}

TEST(RenderAbi, FrameStatistics) {
  cv::Mat f(2, 2, CV_8UC4, cv::Scalar(0, 0, 0, 255));
  f.at<cv::Vec4b>(0, 0) = cv::Vec4b(255, 0, 100, 0);
  auto st = abiFrameStats(f);
  ASSERT_TRUE(st);
  EXPECT_DOUBLE_EQ(st->lit_fraction, 0.25);
  EXPECT_DOUBLE_EQ(st->mean_rgb[0], 63.75);
  EXPECT_DOUBLE_EQ(st->mean_rgb[2], 25.0);
  EXPECT_FALSE(abiFrameStats(cv::Mat(2, 2, CV_8UC1)));
}

}  // namespace
}  // namespace procam::plugins
