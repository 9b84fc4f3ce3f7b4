// calib::solveWallViews on synthetic nodes (tests/unit/geometry/synthetic_wall.hpp): the
// answers a caller gets for the walls it cannot solve, and the per-projector figures.
#include <gtest/gtest.h>

#include <random>

#include "calibration/wall_views_route.hpp"
#include "plane_corners.hpp"
#include "unit/geometry/synthetic_wall.hpp"

using namespace procam;

namespace {

struct Wall {
  procam::testing::SyntheticWall wall;
  std::vector<geom::CameraModel> views;
  std::vector<calib::WallNodes> nodes;
  std::vector<std::pair<int, int>> sizes;
};

// A 3x1 wall seen by two cameras on 2-projector blocks, 0.05 px of noise.
Wall threeInARow() {
  std::mt19937 rng(7);
  Wall w;
  w.wall = procam::testing::syntheticWall(3, 1, rng);
  w.views = procam::testing::blockViews(w.wall, 2, rng);
  for (auto& m : procam::testing::viewMatches(w.wall, w.views, 16, 0.05, rng)) {
    calib::CollineationNodes n;
    n.projector = m.projector_px;
    n.camera = m.view_px;
    n.samples = m.projector_px.size();
    w.nodes.push_back({m.projector, m.view, std::move(n)});
  }
  for (const auto& p : w.wall.projectors) w.sizes.emplace_back(p.width, p.height);
  return w;
}

const geom::Plane kSyntheticWall{Vec3(0, -1, 0), 3.0};  // y = 3, the synthetic wall

TEST(WallViewsNodes, EveryProjectorOnTheWallWithItsFigures) {
  const Wall w = threeInARow();
  auto r =
      calib::solveWallViews(w.sizes, w.views.size(), w.nodes, w.views[0], "left", kSyntheticWall);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->projectors.size(), 3u);
  for (std::size_t p = 0; p < 3; ++p) {
    const auto& s = r->projectors[p];
    EXPECT_GT(s.nodes, 100u);
    EXPECT_EQ(s.samples, s.nodes);  // the synthetic nodes have no outliers
    EXPECT_GT(s.coverage, 0.9);
    // 0.05 px of noise per axis: residuals near 0.05 sqrt(2), in camera pixels.
    EXPECT_NEAR(s.rms_px, 0.05 * std::sqrt(2.0), 0.02);
    EXPECT_LE(procam::testing::planeCornerErrorPx(r->projector_to_plane[p], w.wall.projectors[p]),
              0.5);
  }
  EXPECT_GE(r->projectors[2].cameras, 1u);
}

TEST(WallViewsNodes, UnsolvableWallsAreNamed) {
  const Wall w = threeInARow();
  calib::WallViewsOptions named;
  named.camera_names = {"camera 'left'", "camera 'right'"};
  named.projector_names = {"output 'a'", "output 'b'", "output 'c'"};
  // A fourth projector no camera saw.
  auto sizes = w.sizes;
  sizes.emplace_back(1280, 800);
  named.projector_names.push_back("output 'd'");
  auto unseen = calib::solveWallViews(sizes, 2, w.nodes, w.views[0], "left", kSyntheticWall, named);
  ASSERT_FALSE(unseen);
  EXPECT_EQ(unseen.error().code, ErrorCode::kDegenerate);
  EXPECT_NE(unseen.error().message.find("output 'd'"), std::string::npos) << unseen.error().message;
  EXPECT_NE(unseen.error().message.find("camera 'left'"), std::string::npos);
  named.projector_names.pop_back();
  // A projector the cameras see only a corner of: its collineation would be extrapolated.
  std::vector<calib::WallNodes> corner;
  for (calib::WallNodes n : w.nodes) {
    if (n.projector == 2) {
      calib::CollineationNodes kept;
      for (std::size_t i = 0; i < n.nodes.projector.size(); ++i) {
        if (n.nodes.projector[i].x() < 200 && n.nodes.projector[i].y() < 100) {
          kept.projector.push_back(n.nodes.projector[i]);
          kept.camera.push_back(n.nodes.camera[i]);
        }
      }
      n.nodes = kept;
    }
    corner.push_back(std::move(n));
  }
  auto extrapolated =
      calib::solveWallViews(w.sizes, 2, corner, w.views[0], "left", kSyntheticWall, named);
  ASSERT_FALSE(extrapolated);
  EXPECT_EQ(extrapolated.error().code, ErrorCode::kDegenerate);
  EXPECT_NE(extrapolated.error().message.find("output 'c'"), std::string::npos)
      << extrapolated.error().message;
  // Bad input.
  EXPECT_EQ(
      calib::solveWallViews(w.sizes, 2, w.nodes, w.views[0], "left", geom::Plane{Vec3::Zero(), 1.0})
          .error()
          .code,
      ErrorCode::kInvalidInput);
  EXPECT_EQ(
      calib::solveWallViews(w.sizes, 1, w.nodes, w.views[0], "left", kSyntheticWall).error().code,
      ErrorCode::kInvalidInput);
  auto uneven = w.nodes;
  uneven[0].nodes.camera.pop_back();
  EXPECT_EQ(
      calib::solveWallViews(w.sizes, 2, uneven, w.views[0], "left", kSyntheticWall).error().code,
      ErrorCode::kInvalidInput);
  // The plane behind the reference camera: it does not see the lit wall there.
  EXPECT_EQ(calib::solveWallViews(w.sizes, 2, w.nodes, w.views[0], "left",
                                  geom::Plane{Vec3(0, -1, 0), -5.0})
                .error()
                .code,
            ErrorCode::kDegenerate);
}

}  // namespace
