// The drift check and its corrections on a curved surface the rig model knows as a mesh:
// cylinder3 (three 1280x800 projectors inside a cylinder of radius 3 m, cameras with 1 DN
// read noise, at 1600x1200: curved_drift_scene.hpp), its TRUE wall as the rig's mesh and
// the truth at rest as the rig model. The centre projector's frame is rendered by the virtual rig
// with the projector or a camera bumped, so the true bumped device is known.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "curved_drift_rig.hpp"
#include "drift/camera_correction.hpp"
#include "drift/misregistration.hpp"
#include "drift/projector_camera_map.hpp"
#include "drift/projector_correction.hpp"
#include "drift/shown_light.hpp"
#include "sim/renderer.hpp"
#include "textured_content.hpp"

namespace procam::drift {
namespace {

using namespace testing_curved;

struct View {
  cv::Mat shown, camera, map;
  WorkGrid grid;
};

View viewOf(const CurvedRig& rig, const cv::Mat& framebuffer, const geom::Pose& projector_pose,
            const std::optional<geom::Pose>& camera_pose = std::nullopt) {
  sim::SceneState state = rig.scene.at(0);
  state.projectors.at(kCentre).model.pose = projector_pose;
  if (camera_pose) state.cameras.at(kCamera).model.pose = *camera_pose;
  auto image =
      centreSeen(rig, state, framebuffer, cv::Mat(framebuffer.size(), CV_8U, cv::Scalar(0)));
  EXPECT_TRUE(image) << image.error().message;
  View v;
  v.grid = {framebuffer.size(), 2};
  image->convertTo(v.camera, CV_32F);
  // The frame's light, through the projector's true response.
  auto shown = shownLight(framebuffer, rig.scene.at(0).projectors.at(kCentre).spec.gamma, v.grid);
  EXPECT_TRUE(shown) << shown.error().message;
  if (shown) v.shown = *shown;
  auto map = projectorCameraMap(rig.lit, rig.model.cameras.at(kCamera).model, v.grid);
  EXPECT_TRUE(map) << map.error().message;
  v.map = *map;
  return v;
}

TEST(CurvedDrift, TheMeshMapPutsEveryPixelWhereTheCameraSeesIt) {
  const CurvedRig rig = restingRig();
  const geom::CameraModel cam = rig.model.cameras.at(kCamera).model;
  const WorkGrid grid{{1280, 800}, 2};
  auto map = projectorCameraMap(rig.lit, cam, grid);
  ASSERT_TRUE(map) << map.error().message;
  // Against the analytic cylinder: the pixel's ray meets x^2 + y^2 = 9.
  const geom::CameraModel projector = rig.scene.at(0).projectors.at(kCentre).model;
  double worst = 0;
  int seen = 0;
  for (int y = 0; y < grid.size().height; y += 10) {
    for (int x = 0; x < grid.size().width; x += 10) {
      const cv::Vec2f c = map->at<cv::Vec2f>(y, x);
      if (c[0] < 0) continue;
      ++seen;
      const geom::Ray ray = *projector.backproject(grid.toFramebuffer({x, y}));
      const Vec2 o = ray.origin.head<2>(), d = ray.dir.head<2>();
      const double a = d.squaredNorm(), b = 2 * o.dot(d), cc = o.squaredNorm() - 9;
      const double t = (-b + std::sqrt(b * b - 4 * a * cc)) / (2 * a);
      const Vec2 truth = *cam.project(ray.origin + t * ray.dir);
      worst = std::max(worst, (truth - Vec2(c[0], c[1])).norm());
    }
  }
  std::printf("[ figures  ] mesh map: %d of %d grid samples seen, worst %.4f camera px\n", seen,
              (grid.size().height / 10 + 1) * (grid.size().width / 10 + 1), worst);
  EXPECT_GT(seen, 1000);
  // The facets' 7 um chords, seen from 4 m by a 670 px focal length: under 0.01 px.
  EXPECT_LT(worst, 0.01);
  // A camera outside the cylinder, looking through its wall at the frame: the wall hides
  // every lit point (without the occluder the same camera sees them).
  geom::CameraModel outside = cam;
  const Vec3 eye(4.5, 0.0, 1.6), ahead = (Vec3(0.0, 3.0, 1.75) - eye).normalized();
  const Vec3 right = ahead.cross(Vec3::UnitZ()).normalized(), down = ahead.cross(right);
  outside.pose.R.row(0) = right.transpose();
  outside.pose.R.row(1) = down.transpose();
  outside.pose.R.row(2) = ahead.transpose();
  outside.pose.t = -outside.pose.R * eye;
  const auto seenIn = [&](const LitSurface& lit) {
    auto m = projectorCameraMap(lit, outside, grid);
    EXPECT_TRUE(m);
    cv::Mat x;
    cv::extractChannel(*m, x, 0);
    return cv::countNonZero(x >= 0);
  };
  LitSurface unhidden = rig.lit;
  unhidden.occluder.reset();
  EXPECT_GT(seenIn(unhidden), 10000);
  EXPECT_EQ(seenIn(rig.lit), 0);
}

// A projector whose frames are drawn through a post-rendering warp W standing for its lens
// ([Raskar02] §4.1.3): its pixel d shows pinhole pixel W(d). Tiles made from the geometry
// alone (the bumped projector lights the wall where its pinhole puts W(d); the rig model
// sees that point at the pixel s with W(s) = P X): the pose is fitted as a pinhole to W(d).
TEST(CurvedDrift, APoseIsRefittedThroughTheWarpThatStandsForTheLens) {
  const CurvedRig rig = restingRig();
  const geom::CameraModel rest = rig.scene.at(0).projectors.at(kCentre).model;
  geom::CameraModel bumped = rest;
  bumped.pose = turned(rest.pose, 0.5, -0.3);
  // A smooth field of up to 6 px, and its inverse by fixed-point steps.
  const auto W = [](const Vec2& m) {
    return Vec2(m.x() + 6 * std::sin(m.y() / 300), m.y() + 4 * std::cos(m.x() / 400));
  };
  const auto Winv = [&](const Vec2& p) {
    Vec2 m = p;
    for (int k = 0; k < 50; ++k) m += p - W(m);
    return m;
  };
  const auto onWall = [&](const geom::CameraModel& pinhole, const Vec2& d) {
    auto hit = rig.wall->intersect(*pinhole.backproject(W(d)));
    return hit ? std::optional<Vec3>(hit->point) : std::nullopt;
  };
  LitSurface lit;
  lit.point = [&](const Vec2& s) { return onWall(rest, s); };
  lit.to_pinhole = W;
  Misregistration m;
  for (int y = 100; y < 800; y += 100) {
    for (int x = 100; x < 1280; x += 100) {
      TileShift t;
      t.drawn = Vec2(x, y);
      const Vec3 X = *onWall(bumped, t.drawn);
      t.seen_at = Winv(*rest.project(X));
      t.inlier = true;
      m.tiles.push_back(t);
    }
  }
  rig::RigProjector before = rig.model.projectors.at(kCentre);
  auto c = correctProjector(before, lit, m);
  ASSERT_TRUE(c) << c.error().message;
  geom::CameraModel fitted = rest;
  fitted.pose = c->projector.pose;
  double worst = 0;
  for (const TileShift& t : m.tiles) {
    const Vec3 X = *onWall(bumped, t.drawn);
    worst = std::max(worst, (*fitted.project(X) - *bumped.project(X)).norm());
  }
  std::printf(
      "[ figures  ] through a 6 px warp: %d tiles, pose fit %.2e px, %.2e px from the "
      "bumped pinhole\n",
      c->tiles, c->pose_rms_px, worst);
  // Noise-free tiles: the fit is exact to the solver's tolerance.
  EXPECT_LT(worst, 1e-3);
  // A hole in the surface: tiles seen there are left out, the rest still fit.
  LitSurface holed = lit;
  holed.point = [&](const Vec2& s) { return s.x() < 400 ? std::nullopt : onWall(rest, s); };
  auto h = correctProjector(before, holed, m);
  ASSERT_TRUE(h) << h.error().message;
  EXPECT_LT(h->tiles, c->tiles);
}

TEST(CurvedDrift, ABumpedProjectorIsMeasuredAndItsPoseCorrectedOnTheMesh) {
  const CurvedRig rig = restingRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(kCentre).model.pose;
  const cv::Mat content = texturedContent({1280, 800}, 5, {64, 24, 9});
  {
    const View v = viewOf(rig, content, rest);
    auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
    ASSERT_TRUE(m) << m.error().message;
    std::printf("[ figures  ] cylinder at rest: %d tiles used, rms %.3f px, max %.3f px\n",
                m->tiles_used, m->rms_px, m->max_px);
    EXPECT_GE(m->tiles_used, 30);
    // A fifth of the 0.5 px the daemon acts on: no false trigger from noise.
    EXPECT_LT(m->rms_px, 0.1);
  }
  for (auto [yaw, pitch] : {std::pair{0.5, 0.0}, std::pair{0.0, -2.0}}) {
    SCOPED_TRACE(testing::Message() << "yaw " << yaw << " pitch " << pitch);
    const geom::Pose bumped = turned(rest, yaw, pitch);
    const View v = viewOf(rig, content, bumped);
    auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
    ASSERT_TRUE(m) << m.error().message;
    auto c = correctProjector(rig.model.projectors.at(kCentre), rig.lit, *m);
    ASSERT_TRUE(c) << c.error().message;
    geom::CameraModel truth = rig.scene.at(0).projectors.at(kCentre).model;
    truth.pose = bumped;
    geom::CameraModel fixed = rig.model.projectors.at(kCentre).model();
    const double moved = againstTruth(rig, fixed, truth);
    fixed.pose = c->projector.pose;
    const double after = againstTruth(rig, fixed, truth);
    std::printf(
        "[ figures  ] cylinder, projector bumped yaw %.1f pitch %.1f deg: measured %.2f px "
        "(%d tiles), the rig %.2f px off before and %.3f px after (pose fit %.3f px)\n",
        yaw, pitch, m->rms_px, c->tiles, moved, after, c->pose_rms_px);
    EXPECT_GT(m->rms_px, 0.5);
    // Within half the 0.5 px a corrected rig must reach.
    EXPECT_LT(after, 0.25);
  }
}

TEST(CurvedDrift, ABumpedCameraIsReregisteredFromTheContentOnTheMesh) {
  const CurvedRig rig = restingRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(kCentre).model.pose;
  const cv::Mat content = texturedContent({1280, 800}, 7, {64, 24, 9});
  const rig::RigCamera& before = rig.model.cameras.at(kCamera);
  geom::CameraModel truth = before.model;
  truth.pose = turned(before.model.pose, 0.3, 0.0);
  const View v = viewOf(rig, content, rest, truth.pose);
  auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
  ASSERT_TRUE(m) << m.error().message;
  auto c = correctCamera(before, rig.lit, *m, v.map, v.grid);
  ASSERT_TRUE(c) << c.error().message;
  // The corrected camera against the true bumped one where it sees the centre
  // projector's frame (whose content re-registered it); where it sees the whole display
  // (the side projectors' frames, extrapolated from it) it is reported.
  const sim::SceneState rest_state = rig.scene.at(0);
  double worst = 0, worst_display = 0;
  int n = 0;
  for (int y = 0; y < truth.height; y += 30) {
    for (int x = 0; x < truth.width; x += 30) {
      auto hit = rig.wall->intersect(*truth.backproject({x, y}));
      if (!hit) continue;
      bool framed = false, in_display = false;
      for (std::size_t p = 0; p < rest_state.projectors.size(); ++p) {
        const geom::CameraModel& pm = rest_state.projectors[p].model;
        auto u = pm.project(hit->point);
        const bool in = u && pm.inImage(*u);
        in_display = in_display || in;
        if (p == kCentre) framed = in;
      }
      if (!in_display) continue;
      const double e = (*c->camera.model.project(hit->point) - Vec2(x, y)).norm();
      worst_display = std::max(worst_display, e);
      if (!framed) continue;
      worst = std::max(worst, e);
      ++n;
    }
  }
  ASSERT_GT(n, 100);
  std::printf(
      "[ figures  ] cylinder, camera bumped 0.3 deg: content moved %.2f px; refit %.3f px "
      "over %d tiles, against the true camera %.3f camera px at worst on the frame, %.3f on "
      "the whole display\n",
      m->rms_px, c->pose_rms_px, c->tiles, worst, worst_display);
  // A camera pixel is about three projector pixels here: a tenth of the 0.5 px bound.
  EXPECT_LT(worst, 0.15);
}

}  // namespace
}  // namespace procam::drift
