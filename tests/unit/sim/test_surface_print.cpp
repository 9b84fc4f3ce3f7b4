// A calibration board printed on a wall of the virtual rig: its ink reflects 5 % of
// the paper, and a camera that sees it finds it where the scene puts it, upright.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "calibration/board.hpp"
#include "calibration/board_plane.hpp"
#include "sim/renderer.hpp"
#include "sim_test_util.hpp"

namespace procam::sim {
namespace {

// The flat wall y = 2 with a checkerboard of 4x3 inner corners (5x4 squares of 15 cm,
// 1.05 m x 0.9 m with its one-square margin) centred at (0, 2, 1).
const char* const kBoard =
    "albedo = 0.7\nboard = { spec = \"checker:4x3:0.15\", center = [0.0, 2.0, 1.0] }";

Result<Scene> boardScene() {
  std::string text = testing::flatWallScene("");
  text.replace(text.find("albedo = 0.7"), 12, kBoard);
  return Scene::parse(text, "board.toml", {});
}

TEST(SimSurfacePrint, InkReflectsFivePercentOfThePaper) {
  auto printed = boardScene();
  ASSERT_TRUE(printed) << printed.error().message;
  auto bare = Scene::parse(testing::flatWallScene(""), "bare.toml", {});
  ASSERT_TRUE(bare);
  const SceneState state = printed->at(0);
  const auto& proj = state.projectors.at(0);
  const Framebuffers white{
      {"proj", cv::Mat(proj.spec.height, proj.spec.width, CV_8UC1, cv::Scalar(255))}};
  auto with = Renderer::create(*printed, state, white);
  auto without = Renderer::create(*bare, bare->at(0), white);
  ASSERT_TRUE(with && without);
  // The radiance with the print over the radiance of the bare wall, at the centre of
  // square (column c, row r) counted from the board image's top-left square (the
  // margin). Squares with c + r even are black, except in the margin; the image is
  // 7 x 6 squares of 15 cm, so its top-left corner is at x = -0.525, z = 1.45.
  auto factor = [&](int c, int row) {
    const Vec3 point(-0.525 + 0.15 * (c + 0.5), 2.0, 1.45 - 0.15 * (row + 0.5));
    const Vec3 eye(0.2, 0.0, 1.0);
    const geom::Ray ray{eye, (point - eye).normalized()};
    return with->radianceAlong(ray)[0] / without->radianceAlong(ray)[0];
  };
  EXPECT_NEAR(factor(1, 1), kInkReflectance, 1e-4);  // black
  EXPECT_NEAR(factor(2, 1), 1.0, 1e-4);              // white
  EXPECT_NEAR(factor(3, 3), kInkReflectance, 1e-4);
  EXPECT_NEAR(factor(0, 0), 1.0, 1e-4);   // margin
  EXPECT_NEAR(factor(-2, 1), 1.0, 1e-4);  // off the print
}

TEST(SimSurfacePrint, TheCameraFindsTheBoardOnTheWallUpright) {
  auto scene = boardScene();
  ASSERT_TRUE(scene) << scene.error().message;
  const SceneState state = scene->at(0);
  const auto& proj = state.projectors.at(0);
  auto r = Renderer::create(
      *scene, state,
      {{"proj", cv::Mat(proj.spec.height, proj.spec.width, CV_8UC1, cv::Scalar(255))}});
  ASSERT_TRUE(r);
  auto image = r->renderCamera("cam", {.noise = true, .seed = 3});
  ASSERT_TRUE(image);
  const auto spec = *calib::parseBoard("checker:4x3:0.15");
  auto view = calib::detectBoard(spec, *image);
  ASSERT_TRUE(view) << view.error().message;
  EXPECT_EQ(view->image.size(), 12u);
  const geom::CameraModel& cam = state.cameras.at(0).model;
  auto plane = calib::boardPlane(cam, *view);
  ASSERT_TRUE(plane) << plane.error().message;
  // The wall y = 2, 2 m from the camera: a board 100 px wide (squares of 16 px)
  // gives its normal to about 0.1 px / 100 px rad times the distance-to-size ratio
  // (2): 0.1 degrees; 0.5 allowed, and 1 % of the distance.
  const double normal_deg =
      std::acos(std::min(1.0, plane->plane.n.dot(Vec3::UnitY()))) * 180 / std::numbers::pi;
  EXPECT_LT(normal_deg, 0.5);
  EXPECT_NEAR(plane->plane.d, -2.0, 0.02);
  // Readable from the room: the board's z axis (x right, y down on the print) points
  // into the wall, away from the camera; a mirrored print would turn it round.
  EXPECT_GT(plane->board_pose.R.col(2).z(), 0.5);
}

}  // namespace
}  // namespace procam::sim
