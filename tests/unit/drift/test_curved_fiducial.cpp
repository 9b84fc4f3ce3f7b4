// A fiducial frame on a curved surface the rig model knows as a mesh: cylinder3's centre
// projector (curved_drift_rig.hpp: the truth at rest as the rig, the TRUE wall as its
// mesh) shows a grid of AprilTags, the virtual rig's camera sees it at rest and after the
// projector turned, the side projectors lighting the overlaps grey; the corners found,
// taken back through the check's map of the framebuffer into the camera, give the
// misregistration and the pose the daemon would correct, judged against the true bumped
// projector.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <vector>

#include "curved_drift_rig.hpp"
#include "drift/fiducial_misregistration.hpp"
#include "drift/projector_correction.hpp"
#include "sim/renderer.hpp"
#include "tag_frame.hpp"

namespace procam::drift {
namespace {

using namespace testing_curved;

TEST(CurvedFiducial, TagCornersOnTheMeshGiveTheDriftAndThePose) {
  const CurvedRig rig = restingRig();
  const geom::CameraModel rest = rig.scene.at(0).projectors.at(kCentre).model;
  const auto tags_shown = testing_tags::tagFrame(rest.width, rest.height);
  ASSERT_TRUE(tags_shown);
  const sl::TagGrid& grid = tags_shown->grid;
  const cv::Mat& image = tags_shown->image;
  const std::vector<Vec2>& shown = tags_shown->corners;
  const WorkGrid work{image.size(), 2};
  const geom::CameraModel camera = rig.model.cameras.at(kCamera).model;
  auto map = projectorCameraMap(rig.lit, camera, work);
  ASSERT_TRUE(map) << map.error().message;
  struct Case {
    const char* what;
    double yaw, pitch;
  };
  for (const Case& k : {Case{"at rest", 0.0, 0.0}, Case{"turned 0.5 deg", 0.5, 0.0},
                        Case{"tipped 2 deg", 0.0, -2.0}}) {
    SCOPED_TRACE(k.what);
    geom::CameraModel truth = rest;
    truth.pose = turned(rest.pose, k.yaw, k.pitch);
    sim::SceneState state = rig.scene.at(0);
    state.projectors.at(kCentre).model.pose = truth.pose;
    // The side projectors show grey: their light adds to the tags in the overlaps.
    auto seen = centreSeen(rig, state, image, cv::Mat(image.size(), CV_8U, cv::Scalar(128)));
    ASSERT_TRUE(seen) << seen.error().message;
    // cylinder3's cameras give more than 8 bits: stretched as the daemon does.
    cv::Mat grey = *seen;
    if (grey.type() != CV_8UC1) cv::normalize(*seen, grey, 0, 255, cv::NORM_MINMAX, CV_8U);
    auto tags = sl::detectTagGrid(grid, grey);
    ASSERT_TRUE(tags) << tags.error().message;
    std::vector<FiducialCorner> found;
    for (const sl::TagCorrespondence& c : *tags) found.push_back({c.pattern, c.image});
    auto m = fiducialMisregistration(shown, found, *map, work);
    ASSERT_TRUE(m) << m.error().message;
    std::printf(
        "[ figures  ] cylinder, %s: %d of %d tag corners in the camera's view found, %d "
        "agree; misregistration %.3f px RMS (max %.3f), corners %.3f px about the shift "
        "field\n",
        k.what, static_cast<int>(found.size()), m->tiles_seen, m->tiles_used, m->rms_px, m->max_px,
        m->tile_rms_px);
    EXPECT_FALSE(m->too_plain);
    if (k.yaw == 0 && k.pitch == 0) {
      EXPECT_GE(m->tiles_used, 0.9 * m->tiles_seen);
      // Half the 0.5 px the daemon acts on: no false trigger.
      EXPECT_LT(m->rms_px, 0.25);
      continue;
    }
    EXPECT_GT(m->rms_px, 5.0);
    // On a curved surface a turned projector's corners do not move by one collineation
    // of the framebuffer ([Raskar02] §4.1: through the surface): the far ones may fall
    // outside the shift field's band; the pose is fitted to the many that agree.
    EXPECT_GE(m->tiles_used, m->tiles_seen / 2);
    auto c = correctProjector(rig.model.projectors.at(kCentre), rig.lit, *m);
    ASSERT_TRUE(c) << c.error().message;
    geom::CameraModel fixed = rig.model.projectors.at(kCentre).model();
    fixed.pose = c->projector.pose;
    const double px = againstTruth(rig, fixed, truth);
    std::printf(
        "[ figures  ] cylinder, %s: the pose fitted to %d corners is %.3f px from the "
        "true one (pose fit %.3f px)\n",
        k.what, c->tiles, px, c->pose_rms_px);
    // The corrected rig's bound on a plane (fiducial_misregistration's planar test).
    EXPECT_LE(px, 0.5);
  }
}

TEST(CurvedFiducial, TheMapIsTakenBackToWhereItWasDrawn) {
  const CurvedRig rig = restingRig();
  const WorkGrid work{{1280, 800}, 2};
  auto map = projectorCameraMap(rig.lit, rig.model.cameras.at(kCamera).model, work);
  ASSERT_TRUE(map) << map.error().message;
  // Every seen work pixel found again from 20 work pixels away, to the steps' tolerance.
  double worst = 0;
  int n = 0;
  for (int y = 30; y < work.size().height - 30; y += 23) {
    for (int x = 30; x < work.size().width - 30; x += 23) {
      auto c = mappedCameraPixel(*map, Vec2(x, y));
      if (!c) continue;
      auto w = workPixelSeenAt(*map, *c, Vec2(x + 20, y - 15));
      ASSERT_TRUE(w) << x << "," << y;
      worst = std::max(worst, (*w - Vec2(x, y)).norm());
      ++n;
    }
  }
  std::printf("[ figures  ] map taken back at %d work pixels: worst %.2e work px\n", n, worst);
  ASSERT_GT(n, 200);
  // 1e-3 camera px, a camera pixel being about 1.5 work pixels here.
  EXPECT_LT(worst, 0.01);
  // Off the seen part, and a map of the wrong kind.
  EXPECT_FALSE(workPixelSeenAt(*map, Vec2(-50, -50), Vec2(320, 200)));
  const std::vector<Vec2> shown = {Vec2(100, 100)};
  EXPECT_EQ(fiducialMisregistration(shown, {}, cv::Mat(10, 10, CV_32FC1), work).error().code,
            ErrorCode::kInvalidInput);
  const std::vector<FiducialCorner> bad = {{Vec2(NAN, 0), Vec2(1, 1)}};
  EXPECT_EQ(fiducialMisregistration(shown, bad, *map, work).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::drift
