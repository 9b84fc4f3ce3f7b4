// The display plane from a board on it, seen by one calibrated camera with lens
// distortion (board_views.hpp renders the view: 2x supersampling, 0.6 px blur, 1 DN
// noise).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "board_views.hpp"
#include "calibration/board_plane.hpp"
#include "synthetic_rig.hpp"

using namespace procam;
using namespace procam::calib;

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

struct Seen {
  BoardView view;
  geom::Plane truth;  // world
};

// An aprilgrid of 6x4 tags of 4 cm (0.285 m x 0.185 m) at `pose` (board -> camera).
Seen seeBoard(const geom::CameraModel& cam, const geom::Pose& pose) {
  const auto spec = *parseBoard("aprilgrid:6x4:0.04");
  procam::testing::BoardImage b;
  b.px_per_m = 3000;
  b.pixels = *renderBoard(spec, b.px_per_m);
  // Board point (0, 0) is the board image's outer top-left corner (its first tag's
  // outer corner is one white module in).
  b.origin_px = Vec2(-0.5, -0.5);
  Seen s;
  auto v = detectBoard(
      spec, procam::testing::viewBoard(b, cam, procam::testing::cameraRays(cam), pose, 1.0, 3));
  EXPECT_TRUE(v) << v.error().message;
  if (v) s.view = *v;
  const Vec3 n_world = cam.pose.R.transpose() * pose.R.col(2);
  const Vec3 o_world = cam.pose.R.transpose() * (pose.t - cam.pose.t);
  s.truth = geom::orientedPlane(n_world, o_world);
  return s;
}

}  // namespace

// Over the board's poses of camera calibration (0.45-0.65 m, tilted up to 26 degrees):
// the plane's normal and its distance from the camera. Bounds: corners found to about
// 0.1 px over a board some 300 px across give its tilt to 0.1/300 rad times the
// distance-to-size ratio (about 2), 0.04 degrees; 0.15 degrees and 0.5 % of the distance
// leave room for the detector's bias on a blurred view.
TEST(BoardPlane, PlaneOfABoardSeenByADistortedCamera) {
  const geom::CameraModel cam = procam::testing::camera640();
  const auto poses = procam::testing::boardPoses(0.285, 0.185, 6);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Seen s = seeBoard(cam, poses[i]);
    ASSERT_GE(s.view.image.size(), 48u) << "pose " << i;
    auto p = boardPlane(cam, s.view);
    ASSERT_TRUE(p) << p.error().message;
    const double normal_deg = std::acos(std::min(1.0, p->plane.n.dot(s.truth.n))) * kDegPerRad;
    const Vec3 c = cam.pose.center();
    const double dist = std::abs(s.truth.signedDistance(c));
    const double dist_rel = std::abs(std::abs(p->plane.signedDistance(c)) - dist) / dist;
    std::printf(
        "[ figures  ] pose %zu: %zu points, RMS %.3f px, incidence %.1f deg, normal "
        "%.4f deg, distance %.4f %%\n",
        i, p->points, p->rms_px, p->incidence_deg, normal_deg, 100 * dist_rel);
    EXPECT_LT(p->rms_px, 0.5);
    EXPECT_LT(normal_deg, 0.15) << "pose " << i;
    EXPECT_LT(dist_rel, 5e-3) << "pose " << i;
    // Oriented as every plane procamd writes.
    int k = 0;
    p->plane.n.cwiseAbs().maxCoeff(&k);
    EXPECT_GT(p->plane.n[k], 0);
  }
}

TEST(BoardPlane, BadViewsAreRefusedWithTheirReason) {
  const geom::CameraModel cam = procam::testing::camera640();
  const Seen s = seeBoard(cam, procam::testing::boardPoses(0.285, 0.185, 1)[0]);
  ASSERT_GE(s.view.image.size(), 48u);

  BoardView few = s.view;
  few.image.resize(5);
  few.board.resize(5);
  EXPECT_EQ(boardPlane(cam, few).error().code, ErrorCode::kTooFewPoints);

  BoardView mismatched = s.view;
  mismatched.board.pop_back();
  EXPECT_EQ(boardPlane(cam, mismatched).error().code, ErrorCode::kInvalidInput);

  BoardView nan = s.view;
  nan.image[3].x() = std::nan("");
  EXPECT_EQ(boardPlane(cam, nan).error().code, ErrorCode::kInvalidInput);

  BoardView off_plane = s.view;
  off_plane.board[2].z() = 0.01;
  EXPECT_EQ(boardPlane(cam, off_plane).error().code, ErrorCode::kInvalidInput);

  // One row of the board: a line, around which the board may turn freely.
  BoardView line;
  for (std::size_t i = 0; i < s.view.board.size(); ++i) {
    if (std::abs(s.view.board[i].y() - s.view.board[0].y()) < 1e-9) {
      line.image.push_back(s.view.image[i]);
      line.board.push_back(s.view.board[i]);
    }
  }
  ASSERT_GE(line.image.size(), 6u);
  EXPECT_EQ(boardPlane(cam, line).error().code, ErrorCode::kDegenerate);

  // Image points matched to the wrong board points.
  BoardView shuffled = s.view;
  std::reverse(shuffled.image.begin(), shuffled.image.begin() + 16);
  auto bad = boardPlane(cam, shuffled);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kNoConvergence) << bad.error().message;
}
