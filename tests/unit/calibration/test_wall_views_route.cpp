// Route (b′) with cameras at several positions on the virtual rig: tiled_wall's four
// projectors (half resolution) seen by two cameras that each see one column of them and
// a fifth of the other, under the reference capture conditions (8-bit, 1 DN read
// noise). Only the left camera is calibrated; the right one's pose is never given.
#include <gtest/gtest.h>

#include <cstdio>

#include "calibration/wall_views_route.hpp"
#include "plane_corners.hpp"
#include "rig_capture.hpp"
#include "structured_light/decoder.hpp"

using namespace procam;

namespace {

std::string wallViewsScene() {
  std::string t = procam::testing::sceneText("tiled_wall");
  bool ok = true;
  for (int i = 0; i < 4; ++i) ok = ok && procam::testing::scaleDevice(t, 1280, 800, 0.5);
  const std::size_t cams = t.find("[[cameras]]"), surfaces = t.find("[[surfaces]]");
  if (!ok || cams == std::string::npos || surfaces == std::string::npos) return {};
  // Each camera 3.2 m from the wall, centred 1.2 m off the middle: it sees its column
  // of projectors whole and the other column's first fifth.
  t.replace(cams, surfaces - cams, R"([[cameras]]
name = "cam_l"
resolution = [640, 480]
intrinsics = { fx = 700.0, fy = 700.0, cx = 319.5, cy = 239.5 }
distortion = { k1 = -0.04, k2 = 0.01 }
pose = { position = [-1.2, -0.2, 1.5], look_at = [-1.2, 3.0, 1.5] }
bit_depth = 8
read_noise_dn = 1.0
channels = 1
psf_sigma_px = 0.7
supersamples = 4

[[cameras]]
name = "cam_r"
resolution = [640, 480]
intrinsics = { fx = 704.0, fy = 704.0, cx = 321.0, cy = 238.0 }
distortion = { k1 = -0.03, k2 = 0.008 }
pose = { position = [1.2, -0.2, 1.45], look_at = [1.15, 3.0, 1.55] }
bit_depth = 8
read_noise_dn = 1.0
channels = 1
psf_sigma_px = 0.7
supersamples = 4

)");
  return procam::testing::withIssueLighting(t, "cam_l", "0.02", "bit_depth = 8");
}

struct Seams {
  double rms = 0, max = 0;
  long points = 0;
};

TEST(WallViewsRoute, TwoCamerasThatEachSeeHalfCalibrateTheWholeWall) {
  const std::string text = wallViewsScene();
  ASSERT_FALSE(text.empty()) << "tiled_wall.toml no longer has the lines edited here";
  auto scene = sim::Scene::parse(text, "wall views", {});
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  ASSERT_EQ(state.projectors.size(), 4u);
  ASSERT_EQ(state.cameras.size(), 2u);

  // Each camera's light paths traced once: every projector's frames light them.
  std::vector<sim::StillCamera> filming;
  for (const auto& cam : state.cameras) {
    auto still = sim::StillCamera::create(*scene, state, cam.spec.name);
    ASSERT_TRUE(still) << still.error().message;
    filming.push_back(std::move(*still));
  }
  std::vector<std::pair<int, int>> sizes;
  std::vector<calib::WallNodes> nodes;
  for (std::size_t p = 0; p < state.projectors.size(); ++p) {
    const auto& proj = state.projectors[p];
    sl::PatternOptions o;
    o.width = proj.model.width;
    o.height = proj.model.height;
    o.mode = sl::Mode::kGrayPhase;
    o.phase_steps = 3;
    auto set = sl::makePatternSet(o);
    ASSERT_TRUE(set) << set.error().message;
    std::vector<std::vector<cv::Mat>> captures(state.cameras.size());
    for (std::size_t f = 0; f < set->frames.size(); ++f) {
      const sim::Framebuffers shown = {{proj.spec.name, sl::renderFrame(*set, f)}};
      for (std::size_t c = 0; c < state.cameras.size(); ++c) {
        auto image = filming[c].capture(shown, {.noise = true, .seed = 1000 * (10 * p + c) + f});
        ASSERT_TRUE(image) << image.error().message;
        captures[c].push_back(*image);
      }
    }
    for (std::size_t c = 0; c < state.cameras.size(); ++c) {
      auto d = sl::decode(*set, captures[c]);
      ASSERT_TRUE(d) << d.error().message;
      geom::CameraModel model = state.cameras[c].model;
      // Only the reference camera is calibrated: the other keeps its intrinsics (for its
      // lens) and no pose.
      if (c != 0) model.pose = geom::Pose{};
      const calib::DecodedView view{state.cameras[c].spec.name, model, std::move(*d)};
      auto seen = calib::wallSighting(*set, view);
      ASSERT_TRUE(seen) << seen.error().message;
      const std::string what =
          seen->nodes ? std::to_string(seen->nodes->projector.size()) + " nodes" : seen->why;
      std::printf("[ figures  ] %s sees %s: %s\n", state.cameras[c].spec.name.c_str(),
                  proj.spec.name.c_str(), what.c_str());
      if (seen->nodes) nodes.push_back({p, c, std::move(*seen->nodes)});
    }
    sizes.emplace_back(set->options.width, set->options.height);
  }
  const geom::Plane wall{Vec3(0, -1, 0), 3.0};  // y = 3, what an installer measures
  auto solved = calib::solveWallViews(sizes, state.cameras.size(), nodes, state.cameras[0].model,
                                      state.cameras[0].spec.name, wall);
  ASSERT_TRUE(solved) << solved.error().message;
  const calib::WallViewsResult& r = *solved;
  // Corners of each projector's image through the estimate onto the wall, seen by the
  // true projector: the keystone bound (0.5 px) holds for every projector, also those
  // the calibrated camera sees only a fifth of.
  double worst_corner = 0;
  for (std::size_t p = 0; p < state.projectors.size(); ++p) {
    worst_corner = std::max(worst_corner, procam::testing::planeCornerErrorPx(
                                              r.projector_to_plane[p], state.projectors[p].model));
  }
  // Seams: plane points (every 2 mm) two projectors show by the estimate; where the
  // true projectors put the two pixels, apart, in the first one's pixels.
  Seams s;
  double sq = 0;
  const geom::PlaneBasis& basis = r.projector_to_plane[0].basis;
  std::vector<Mat3> to_pixel;
  for (const auto& e : r.projector_to_plane) to_pixel.push_back(e.H.inverse());
  for (double b = -2.0; b < 2.0; b += 0.002) {
    for (double a = -2.5; a < 2.5; a += 0.002) {
      const Vec3 world = basis.toWorld(Vec2(a, b));
      std::vector<std::pair<std::size_t, Vec3>> shown;  // projector, true wall point
      for (std::size_t p = 0; p < to_pixel.size(); ++p) {
        const Vec3 q = to_pixel[p] * r.projector_to_plane[p].basis.toPlane(world).homogeneous();
        if (!(q.z() > 0)) continue;
        const Vec2 px = q.hnormalized();
        const auto& truth = state.projectors[p].model;
        if (!truth.inImage(px)) continue;
        auto ray = truth.backproject(px);
        if (!ray || std::abs(ray->dir.y()) < 1e-9) continue;
        shown.push_back({p, ray->origin + ray->dir * ((3.0 - ray->origin.y()) / ray->dir.y())});
      }
      for (std::size_t i = 0; i < shown.size(); ++i) {
        for (std::size_t j = i + 1; j < shown.size(); ++j) {
          const auto& first = state.projectors[shown[i].first].model;
          auto pi = first.project(shown[i].second), pj = first.project(shown[j].second);
          if (!pi || !pj) continue;
          const double e = (*pi - *pj).norm();
          sq += e * e;
          s.max = std::max(s.max, e);
          ++s.points;
        }
      }
    }
  }
  s.rms = s.points ? std::sqrt(sq / double(s.points)) : 0;
  int deepest = 0;
  for (int d : r.tree.chain_views) deepest = std::max(deepest, d);
  std::printf(
      "[ figures  ] 4 projectors from 2 cameras (chains up to %d): corners within %.3f px of "
      "the truth, seams over %ld points RMS %.3f px max %.3f px; residual %.3f px RMS (chain "
      "%.3f), %d iterations\n",
      deepest, worst_corner, s.points, s.rms, s.max, r.tree.rms_px, r.tree.chain_rms_px,
      r.tree.iterations);
  EXPECT_LE(worst_corner, 0.5);
  EXPECT_GT(s.points, 10000);
  EXPECT_LE(s.rms, 0.3);
  EXPECT_LE(s.max, 1.0);
}

}  // namespace
