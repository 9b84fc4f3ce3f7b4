// A moved wall told from a moved projector by two fixed cameras watching the content, or
// by one camera and the projector: wall_oblique with a second camera, the rig model its
// truth at rest, the cameras' frames rendered by the virtual rig after the wall moved
// 1 cm or the projector turned or slid. Each camera's drift check measures the
// misregistration; the two checks' tiles (or one check's tiles and the projector's
// pixels drawn), triangulated, put the wall where it now stands.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "blend/rig_tiles.hpp"
#include "drift/misregistration.hpp"
#include "drift/projector_camera_map.hpp"
#include "drift/shown_light.hpp"
#include "drift/wall_from_views.hpp"
#include "second_camera.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "textured_content.hpp"

namespace procam::drift {
namespace {

std::string wallObliqueWithTwoCameras(const std::string& events) {
  const auto text = sim::builtinSceneText("wall_oblique");
  EXPECT_TRUE(text) << "no built-in wall_oblique";
  return std::string(text.value_or("")) + "\n" + kSecondCamera + events;
}

struct Checked {
  Misregistration drift;
  cv::Mat map;
  WorkGrid grid;
};

// Both cameras' drift checks at scene time 2 s (after the event at 1 s), against the
// rig model at rest.
std::vector<Checked> checkBoth(const sim::Scene& scene, const rig::RigModel& rest,
                               const cv::Mat& content) {
  auto tile = blend::displayTile(rest.projectors.at(0), rest.surface);
  EXPECT_TRUE(tile) << tile.error().message;
  auto renderer = sim::Renderer::create(scene, scene.at(2.0), {{"proj", content}});
  EXPECT_TRUE(renderer) << renderer.error().message;
  std::vector<Checked> out;
  for (const rig::RigCamera& cam : rest.cameras) {
    auto image = renderer->renderCamera(cam.name);
    EXPECT_TRUE(image) << image.error().message;
    Checked c;
    c.grid = {content.size(), 2};
    cv::Mat camera;
    image->convertTo(camera, CV_32F);
    // The frame's light, through the projector's true response.
    auto light = shownLight(content, scene.at(0).projectors.at(0).spec.gamma, c.grid);
    EXPECT_TRUE(light) << light.error().message;
    const cv::Mat shown = light ? *light : cv::Mat();
    auto map = projectorCameraMap(tile->projector_to_plane, cam.model, c.grid);
    EXPECT_TRUE(map) << map.error().message;
    c.map = *map;
    auto m = measureMisregistration(shown, camera, c.map, c.grid);
    EXPECT_TRUE(m) << m.error().message;
    c.drift = *m;
    out.push_back(std::move(c));
  }
  return out;
}

TEST(WallFromViews, AMovedWallIsToldFromAMovedProjector) {
  const cv::Mat content = texturedContent({1920, 1080}, 7, {96, 32, 12});
  struct Case {
    const char* what;
    std::string events;
    double offset_m;  // how far the wall stands from the rig's plane
  };
  const Case cases[] = {
      {"at rest", "", 0.0},
      {"wall moved 1 cm back",
       "[[events]]\nt = 1.0\ntarget = \"wall\"\nmove_m = [0.0, 0.01, 0.0]\n", -0.01},
      {"projector turned 0.5 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.5, 0.0, 0.0]\n", 0.0},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    auto scene = sim::Scene::parse(wallObliqueWithTwoCameras(k.events), "wall2.toml", {});
    ASSERT_TRUE(scene) << scene.error().message;
    auto rest = sim::truthRig(*scene, 0.0);
    ASSERT_TRUE(rest && rest->surface.plane && rest->cameras.size() == 2);
    const std::vector<Checked> c = checkBoth(*scene, *rest, content);
    ASSERT_EQ(c.size(), 2u);
    const WallView a{&rest->cameras[0].model, &c[0].drift, &c[0].map, c[0].grid};
    const WallView b{&rest->cameras[1].model, &c[1].drift, &c[1].map, c[1].grid};
    auto seen = wallFromTwoViews(a, b, *rest->surface.plane);
    ASSERT_TRUE(seen) << seen.error().message;
    // The wall's plane is y = 3 with its normal towards -y: moved back, it stands at
    // signed distance -1 cm from the rig's plane.
    std::printf(
        "[ figures  ] %s: misregistration %.2f / %.2f px in the two cameras; %d content "
        "points triangulated, %.2f mm RMS about their plane, %.2f mm (standard error %.2f) "
        "from the rig's, tilted %.3f deg: %s\n",
        k.what, c[0].drift.rms_px, c[1].drift.rms_px, seen->points, 1e3 * seen->rms_m,
        1e3 * seen->offset_m, 1e3 * seen->offset_se_m, seen->tilt_deg,
        wallMoved(*seen) ? "the wall moved" : "the wall stands");
    EXPECT_GT(seen->points, 50);
    // Within half the 2 mm the decision needs (wallMoved's default): the wall's position
    // is then never mistaken either way.
    EXPECT_NEAR(seen->offset_m, k.offset_m, 1e-3);
    EXPECT_EQ(wallMoved(*seen), k.offset_m != 0.0);
  }
}

// One camera: the projector is the second view. Its ray through the pixel drawn meets
// the camera's ray through where the content was found only while both stand where the
// rig has them: a moved wall is measured, a turned projector is refused.
TEST(WallFromViews, OneCameraAndTheProjectorTellAMovedWallFromATurnedProjector) {
  const cv::Mat content = texturedContent({1920, 1080}, 7, {96, 32, 12});
  struct Case {
    const char* what;
    std::string events;
    std::optional<double> offset_m;  // nullopt: refused
  };
  const Case cases[] = {
      {"at rest", "", std::nullopt},  // nothing moved: nothing to tell
      {"wall moved 1 cm back",
       "[[events]]\nt = 1.0\ntarget = \"wall\"\nmove_m = [0.0, 0.01, 0.0]\n", -0.01},
      {"wall moved 1 cm forward",
       "[[events]]\nt = 1.0\ntarget = \"wall\"\nmove_m = [0.0, -0.01, 0.0]\n", 0.01},
      {"projector turned 0.05 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.05, 0.0, 0.0]\n", std::nullopt},
      {"projector turned 0.5 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.5, 0.0, 0.0]\n", std::nullopt},
      {"projector tipped 0.5 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.0, -0.5, 0.0]\n", std::nullopt},
      {"projector rolled 0.5 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.0, 0.0, 0.5]\n", std::nullopt},
      {"projector turned and tipped 0.3 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.3, 0.3, 0.0]\n", std::nullopt},
      {"projector turned and tipped 0.3 deg the other way",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.3, -0.3, 0.0]\n", std::nullopt},
      {"projector lifted 1 cm",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nmove_m = [0.0, 0.0, 0.01]\n", std::nullopt},
      {"projector slid 1 cm sideways",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nmove_m = [0.01, 0.0, 0.0]\n", std::nullopt},
      {"projector tipped 2 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.0, -2.0, 0.0]\n", std::nullopt},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    auto scene = sim::Scene::parse(wallObliqueWithTwoCameras(k.events), "wall2.toml", {});
    ASSERT_TRUE(scene) << scene.error().message;
    auto rest = sim::truthRig(*scene, 0.0);
    ASSERT_TRUE(rest && rest->surface.plane && !rest->projectors.empty());
    const std::vector<Checked> c = checkBoth(*scene, *rest, content);
    ASSERT_EQ(c.size(), 2u);
    auto tile = blend::displayTile(rest->projectors[0], rest->surface);
    ASSERT_TRUE(tile) << tile.error().message;
    for (std::size_t i = 0; i < 2; ++i) {
      const WallView v{&rest->cameras[i].model, &c[i].drift, &c[i].map, c[i].grid};
      auto seen =
          wallFromOneCamera(rest->projectors[0], tile->projector_to_plane, v, *rest->surface.plane);
      if (!seen) {
        std::printf("[ figures  ] %s, camera %zu alone: misregistration %.2f px; %s\n", k.what,
                    i + 1, c[i].drift.rms_px, seen.error().message.c_str());
        EXPECT_FALSE(k.offset_m.has_value()) << seen.error().message;
        EXPECT_TRUE(seen.error().code == ErrorCode::kTooFewPoints ||
                    seen.error().code == ErrorCode::kDegenerate)
            << seen.error().message;
        continue;
      }
      std::printf(
          "[ figures  ] %s, camera %zu alone: misregistration %.2f px; the rays of %d of %d "
          "content points met (%.2f mm RMS apart, the content shifted %.2f mm RMS), %.2f mm "
          "RMS about their plane, %.2f mm (standard error %.2f) from the rig's, tilted %.3f "
          "deg (a moved projector would have turned %.4f deg): %s\n",
          k.what, i + 1, c[i].drift.rms_px, seen->points, seen->rays, 1e3 * seen->gap_rms_m,
          1e3 * seen->shift_rms_m, 1e3 * seen->rms_m, 1e3 * seen->offset_m, 1e3 * seen->offset_se_m,
          seen->tilt_deg, seen->projector_turn_deg,
          wallMoved(*seen) ? "the wall moved" : "the wall stands");
      ASSERT_TRUE(k.offset_m.has_value());
      EXPECT_GT(seen->points, 50);
      EXPECT_GE(seen->points, kMinMetShare * seen->rays);
      EXPECT_LE(seen->gap_rms_m, kMaxGapShare * seen->shift_rms_m);
      // Within half the 2 mm the decision needs, as with two cameras.
      EXPECT_NEAR(seen->offset_m, *k.offset_m, 1e-3);
      EXPECT_EQ(wallMoved(*seen), *k.offset_m != 0.0);
      // Not turned: the rig's plane moved, through the true wall (y = 3 - offset).
      const geom::Plane keep = wallToKeep(*seen);
      EXPECT_EQ(keep.n, rest->surface.plane->n);
      EXPECT_NEAR(keep.signedDistance(Vec3(0.0, 3.0 - *k.offset_m, 1.5)), 0.0, 1e-3);
    }
  }
}

TEST(WallFromViews, AMoveOrTurnCountsOnlyAboveItsNoise) {
  WallSeen seen;
  seen.offset_m = 0.003;
  seen.offset_se_m = 0.0001;
  EXPECT_TRUE(wallMoved(seen));
  seen.offset_se_m = 0.001;  // three standard errors: noise
  EXPECT_FALSE(wallMoved(seen));
  seen = {};
  seen.tilt_deg = 0.5;
  seen.tilt_se_deg = 0.2;  // a small patch of noisy points
  EXPECT_FALSE(wallMoved(seen));
  seen.tilt_se_deg = 0.05;
  EXPECT_TRUE(wallMoved(seen));
  seen.tilt_deg = 0.2;  // significant, but under the bound
  seen.tilt_se_deg = 0.01;
  EXPECT_FALSE(wallMoved(seen));
  // The fitted plane is kept when it turned beyond its noise (a turn under wallMoved's
  // bound too, once the wall moved); else the rig's plane, shifted.
  seen.plane = {Vec3(0, 0.6, 0.8), -1};
  seen.shifted = {Vec3::UnitY(), -3.01};
  EXPECT_TRUE(wallTurned(seen));
  EXPECT_EQ(wallToKeep(seen).n, Vec3(0, 0.6, 0.8));
  seen.tilt_se_deg = 0.05;  // within six standard errors
  EXPECT_FALSE(wallTurned(seen));
  EXPECT_EQ(wallToKeep(seen).n, Vec3::UnitY());
  EXPECT_EQ(wallToKeep(seen).d, -3.01);
  seen.tilt_se_deg = 0.01;  // significant, but from one camera under its floor
  seen.tilt_floor_deg = kOneCameraTiltFloorDeg;
  seen.tilt_deg = 0.08;
  EXPECT_FALSE(wallTurned(seen));
  seen.tilt_deg = 0.2;
  EXPECT_TRUE(wallTurned(seen));
}

TEST(WallFromViews, TooFewCommonTilesAndBadViewsAreRefused) {
  Misregistration none;
  const cv::Mat map(540, 960, CV_32FC2, cv::Scalar(-1, -1));
  const WorkGrid grid{{1920, 1080}, 2};
  const geom::CameraModel cam;
  const WallView a{&cam, &none, &map, grid};
  EXPECT_EQ(wallFromTwoViews(a, a, geom::Plane{}).error().code, ErrorCode::kTooFewPoints);
  WallView missing = a;
  missing.map = nullptr;
  EXPECT_EQ(wallFromTwoViews(a, missing, geom::Plane{}).error().code, ErrorCode::kInvalidInput);
  const cv::Mat small(10, 10, CV_32FC2);
  WallView wrong = a;
  wrong.map = &small;
  EXPECT_EQ(wallFromTwoViews(wrong, a, geom::Plane{}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(wallFromProjectorAndView(cam, a, geom::Plane{}).error().code, ErrorCode::kTooFewPoints);
  EXPECT_EQ(wallFromProjectorAndView(cam, wrong, geom::Plane{}).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::drift
