// The adaptive scan and the AprilTag grid on views rendered by the virtual rig
// (drivers/sim), under the reference capture conditions (8 bits, read noise 1 DN,
// ambient 10%).
#include <gtest/gtest.h>

#include <set>

#include "geometry/homography.hpp"
#include "geometry/intersect.hpp"
#include "structured_light/adaptive_scan.hpp"
#include "unit/calibration/issue_scenes.hpp"
#ifdef PROCAM_HAVE_APRILTAG_GRID
#include "structured_light/apriltag_grid.hpp"
#endif

using namespace procam;

namespace {

sim::Scene parse(const std::string& text) {
  auto s = sim::Scene::parse(text, "test scene", {});
  EXPECT_TRUE(s) << s.error().message;
  return std::move(*s);
}

sl::CaptureFn rigCapture(const sim::Scene& scene, const std::string& camera, int* calls) {
  return [&scene, camera, calls](const sl::PatternSet& set) -> Result<std::vector<cv::Mat>> {
    ++*calls;
    auto c = procam::testing::capture(scene, set, 40 + *calls, {camera});
    if (!c) return tl::unexpected(c.error());
    return c->at(camera);
  };
}

sl::AdaptiveOptions adaptiveOptions(const geom::CameraModel& camera,
                                    const geom::CameraModel& projector) {
  sl::AdaptiveOptions o;
  o.full = {.width = projector.width,
            .height = projector.height,
            .mode = sl::Mode::kGrayPhase,
            .phase_steps = 4};
  o.undistort = [camera](const Vec2& p) {
    auto u = camera.undistortPixel(p);
    return u ? *u : p;
  };
  return o;
}

}  // namespace

// wall_oblique is one plane: the coarse 16x12 pass finds it planar and stops with the
// block correspondences, whose homography transfers every lit camera pixel to its
// projector pixel. The blocks are 60x45 projector px and their centroids are biased
// to second order (adaptive_scan.hpp), so the transfer error is bounded by a small
// fraction of a block: 1 px RMS (1.7% of a block) and 3 px at worst.
TEST(RigScan, WallObliqueIsPlanarAfterTheCoarsePass) {
  const std::string text = procam::testing::issueWallOblique(0.0);
  ASSERT_FALSE(text.empty());
  const sim::Scene scene = parse(text);
  const sim::SceneState state = scene.at(0);
  const geom::CameraModel& camera = state.camera("cam")->model;
  const geom::CameraModel& projector = state.projectors[0].model;
  int calls = 0;
  auto r = sl::scanAdaptive(adaptiveOptions(camera, projector), rigCapture(scene, "cam", &calls));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->planar) << r->reason;
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(r->frames_used, 2 + 2 * 4 + 2 * 4);  // white, black, 4 + 4 Gray bits with inverses
  EXPECT_FALSE(r->full);
  EXPECT_GE(r->coarse.camera.size(), 8u);  // a homography needs 4; the test needs 8

  auto renderer = sim::Renderer::create(scene, state, {});
  auto truth = renderer->cameraTruth("cam");
  ASSERT_TRUE(truth);
  double sum = 0, worst = 0;
  int n = 0;
  for (int y = 0; y < camera.height; y += 2)
    for (int x = 0; x < camera.width; x += 2) {
      if (!truth->lit[0].at<std::uint8_t>(y, x)) continue;
      auto ideal = camera.undistortPixel(Vec2(x, y));
      ASSERT_TRUE(ideal);
      auto p = geom::applyHomography(r->coarse.H, *ideal);
      ASSERT_TRUE(p);
      const cv::Vec2f t = truth->projector_pixel[0].at<cv::Vec2f>(y, x);
      const double e = (*p - Vec2(t[0], t[1])).norm();
      sum += e * e;
      worst = std::max(worst, e);
      ++n;
    }
  ASSERT_GT(n, 1000);
  const double rms = std::sqrt(sum / n);
  EXPECT_LE(rms, 1.0);
  EXPECT_LE(worst, 3.0);
  std::printf(
      "[ figures  ] wall_oblique: %d frames, %zu blocks, fit RMS %.3f px (tolerance %.3f), "
      "transfer error %.3f px RMS, %.3f px max over %d lit pixels; %s\n",
      r->frames_used, r->coarse.camera.size(), r->coarse.rms_px, r->coarse.tolerance_px, rms, worst,
      n, r->reason.c_str());
}

// corner_stereo's two walls are not one homography: the full set follows.
TEST(RigScan, CornerStereoIsNonPlanarAndGetsTheFullSet) {
  const std::string text = procam::testing::issueCornerStereo();
  ASSERT_FALSE(text.empty());
  const sim::Scene scene = parse(text);
  const sim::SceneState state = scene.at(0);
  const geom::CameraModel& camera = state.camera("cam_left")->model;
  const geom::CameraModel& projector = state.projectors[0].model;
  const sl::AdaptiveOptions o = adaptiveOptions(camera, projector);
  int calls = 0;
  auto r = sl::scanAdaptive(o, rigCapture(scene, "cam_left", &calls));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->planar) << r->reason;
  EXPECT_EQ(calls, 2);
  auto full = sl::makePatternSet(o.full);
  ASSERT_TRUE(full);
  EXPECT_EQ(r->frames_used, 18 + static_cast<int>(full->frames.size()));
  ASSERT_TRUE(r->full);
  auto renderer = sim::Renderer::create(scene, state, {});
  auto truth = renderer->cameraTruth("cam_left");
  ASSERT_TRUE(truth);
  EXPECT_GT(r->full->decoded, 0.9 * cv::countNonZero(truth->lit[0]));
  std::printf("[ figures  ] corner_stereo: %d frames; %s\n", r->frames_used, r->reason.c_str());
}

#ifdef PROCAM_HAVE_APRILTAG_GRID
// The projector shows a tag grid on wall_oblique (camera at half resolution); every
// tag is found and each corner lies where the true projector, wall and camera put it.
// libapriltag's corners sit +0.5 px off the pixel-centre convention: a missed
// correction would show as a 0.5 px mean offset.
TEST(RigScan, AprilTagGridOnARenderedView) {
  std::string text = procam::testing::sceneText("wall_oblique");
  ASSERT_TRUE(procam::testing::scaleDevice(text, 1920, 1080, 0.5));
  ASSERT_TRUE(procam::testing::scaleDevice(text, 1280, 960, 0.5));
  ASSERT_TRUE(procam::testing::edit(text, "exposure = 1.0\n", ""));
  ASSERT_TRUE(procam::testing::edit(text, "read_noise_dn = 0.8", "read_noise_dn = 1.0"));
  text = procam::testing::withIssueLighting(text, "cam", "0.02", "bit_depth = 8");
  const sim::Scene scene = parse(text);
  const sim::SceneState state = scene.at(0);
  const geom::CameraModel& camera = state.camera("cam")->model;
  const geom::CameraModel& projector = state.projectors[0].model;
  auto grid = sl::makeTagGrid({.width = projector.width, .height = projector.height});
  ASSERT_TRUE(grid);
  auto shown = sl::renderTagGrid(*grid);
  ASSERT_TRUE(shown);
  auto renderer = sim::Renderer::create(scene, state, {{"proj", *shown}});
  ASSERT_TRUE(renderer);
  auto image = renderer->renderCamera("cam", {.noise = true, .seed = 5});
  ASSERT_TRUE(image);
  auto found = sl::detectTagGrid(*grid, *image);
  ASSERT_TRUE(found) << found.error().message;
  std::set<int> ids;
  for (const auto& c : *found) ids.insert(c.id);
  EXPECT_EQ(ids.size(), grid->tags.size());

  geom::Plane wall;  // y = 3
  wall.n = Vec3(0, -1, 0);
  wall.d = 3;
  Vec2 mean = Vec2::Zero();
  double sum = 0, worst = 0;
  for (const auto& c : *found) {
    auto ray = projector.backproject(c.pattern);
    ASSERT_TRUE(ray);
    auto hit = geom::intersectPlane(*ray, wall);
    ASSERT_TRUE(hit);
    auto expected = camera.project(hit->point);
    ASSERT_TRUE(expected);
    const Vec2 e = c.image - *expected;
    mean += e;
    sum += e.squaredNorm();
    worst = std::max(worst, e.norm());
  }
  mean /= static_cast<double>(found->size());
  const double rms = std::sqrt(sum / found->size());
  EXPECT_LT(mean.norm(), 0.1);  // the convention: a missed +0.5 px shows here
  EXPECT_LT(rms, 0.3);
  EXPECT_LT(worst, 1.0);
  std::printf(
      "[ figures  ] AprilTag grid: %zu of %zu tags, %zu corners; corner error %.3f px RMS, "
      "%.3f px max, mean (%.3f, %.3f) camera px\n",
      ids.size(), grid->tags.size(), found->size(), rms, worst, mean.x(), mean.y());
}
#endif
