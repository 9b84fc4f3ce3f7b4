// Drift seen in a fiducial frame: wall_oblique's projector shows a grid of AprilTags, the
// virtual rig's camera sees it at rest and after the projector turned 0.5 degrees; the
// tag corners the camera finds give the misregistration where plain content gives none,
// and the projector's pose fitted to them (drift/projector_correction.hpp) is checked
// against the true one.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "blend/rig_tiles.hpp"
#include "drift/fiducial_misregistration.hpp"
#include "drift/projector_correction.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "tag_frame.hpp"

namespace procam::drift {
namespace {

std::string wallOblique(const std::string& events) {
  const auto text = sim::builtinSceneText("wall_oblique");
  EXPECT_TRUE(text) << "no built-in wall_oblique";
  return std::string(text.value_or("")) + "\n" + events;
}

// The largest distance, in the true projector's pixels, between a framebuffer pixel and
// where the true projector puts the wall point `model` gives it.
double againstTruth(const geom::CameraModel& model, const geom::CameraModel& truth,
                    const geom::Plane& wall) {
  double worst = 0;
  for (int y = 0; y < model.height; y += 40) {
    for (int x = 0; x < model.width; x += 40) {
      auto ray = model.backproject({x, y});
      auto hit = ray ? geom::intersectPlane(*ray, wall) : std::nullopt;
      auto back = hit ? truth.project(hit->point) : std::nullopt;
      if (!back) return 1e9;
      worst = std::max(worst, (*back - Vec2(x, y)).norm());
    }
  }
  return worst;
}

TEST(FiducialMisregistration, TagCornersGiveTheDriftAndThePose) {
  const auto tags_shown = testing_tags::tagFrame(1920, 1080);
  ASSERT_TRUE(tags_shown);
  const sl::TagGrid& grid = tags_shown->grid;
  const cv::Mat& image = tags_shown->image;
  const std::vector<Vec2>& shown = tags_shown->corners;
  struct Case {
    const char* what;
    std::string events;
    bool moved;
  };
  const Case cases[] = {
      {"at rest", "", false},
      {"projector turned 0.5 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.5, 0.0, 0.0]\n", true},
      {"projector tipped 2 deg",
       "[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [0.0, -2.0, 0.0]\n", true},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    auto scene = sim::Scene::parse(wallOblique(k.events), "wall.toml", {});
    ASSERT_TRUE(scene) << scene.error().message;
    auto rest = sim::truthRig(*scene, 0.0);
    ASSERT_TRUE(rest && rest->surface.plane && !rest->cameras.empty());
    auto tile = blend::displayTile(rest->projectors.at(0), rest->surface);
    ASSERT_TRUE(tile) << tile.error().message;
    auto renderer = sim::Renderer::create(*scene, scene->at(2.0), {{"proj", image}});
    ASSERT_TRUE(renderer) << renderer.error().message;
    auto seen = renderer->renderCamera("cam");
    ASSERT_TRUE(seen) << seen.error().message;
    auto tags = sl::detectTagGrid(grid, *seen);
    ASSERT_TRUE(tags) << tags.error().message;
    std::vector<FiducialCorner> found;
    for (const sl::TagCorrespondence& c : *tags) found.push_back({c.pattern, c.image});
    auto m =
        fiducialMisregistration(shown, found, tile->projector_to_plane, rest->cameras[0].model);
    ASSERT_TRUE(m) << m.error().message;
    const geom::CameraModel truth = scene->at(2.0).projectors.at(0).model;
    std::printf(
        "[ figures  ] %s: %d of %d tag corners in the camera's view found, %d agree; "
        "misregistration %.3f px RMS (max %.3f), corners %.3f px about one collineation\n",
        k.what, static_cast<int>(found.size()), m->tiles_seen, m->tiles_used, m->rms_px, m->max_px,
        m->tile_rms_px);
    EXPECT_FALSE(m->too_plain);
    EXPECT_GE(m->tiles_used, 0.9 * m->tiles_seen);
    // The drift check's scatter: at rest well under the 0.5 px threshold (its half: no
    // false trigger), a corner's own position to a fraction of a pixel.
    EXPECT_LT(m->tile_rms_px, 0.3);
    if (!k.moved) {
      EXPECT_LT(m->rms_px, 0.25);
      continue;
    }
    EXPECT_GT(m->rms_px, 10.0);
    auto c = correctProjector(rest->projectors[0], tile->projector_to_plane, *m);
    ASSERT_TRUE(c) << c.error().message;
    const double px = againstTruth(c->projector.model(), truth, *rest->surface.plane);
    std::printf("[ figures  ] %s: the pose fitted to %d corners is %.3f px from the true one\n",
                k.what, c->tiles, px);
    EXPECT_LE(px, 0.5);
  }
}

TEST(FiducialMisregistration, BadInputIsRefusedAndTooFewCornersArePlain) {
  geom::PlaneHomography tile;
  tile.basis = {Vec3(0, 3, 0), Vec3::UnitX(), Vec3::UnitZ()};
  geom::CameraModel cam;
  cam.width = 640;
  cam.height = 480;
  cam.K.fx = cam.K.fy = 500;
  cam.K.cx = 319.5;
  cam.K.cy = 239.5;
  tile.H = Mat3::Zero();
  const std::vector<Vec2> shown = {Vec2(0, 0)};
  EXPECT_EQ(fiducialMisregistration(shown, {}, tile, cam).error().code, ErrorCode::kInvalidInput);
  tile.H = Mat3::Identity();
  const std::vector<Vec2> nan = {Vec2(NAN, 0)};
  EXPECT_EQ(fiducialMisregistration(nan, {}, tile, cam).error().code, ErrorCode::kInvalidInput);
  const std::vector<FiducialCorner> bad = {{Vec2(0, 0), Vec2(INFINITY, 1)}};
  EXPECT_EQ(fiducialMisregistration(shown, bad, tile, cam).error().code, ErrorCode::kInvalidInput);
  auto none = fiducialMisregistration(shown, {}, tile, cam);
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->too_plain);
  EXPECT_EQ(none->tiles_used, 0);
}

}  // namespace
}  // namespace procam::drift
