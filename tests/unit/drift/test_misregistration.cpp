// The drift check and its pose correction on wall_oblique (one 1920x1080 projector at
// 30 deg yaw / 15 deg pitch to a wall, a fixed 1280x960 camera with 0.8 DN read noise):
// the rig model is the scene's truth at rest; the camera's frame is rendered by the
// virtual rig with the projector bumped, so the true shift of every tile and the true
// bumped projector are known.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "blend/rig_tiles.hpp"
#include "core/units.hpp"
#include "drift/camera_correction.hpp"
#include "drift/misregistration.hpp"
#include "drift/projector_camera_map.hpp"
#include "drift/projector_correction.hpp"
#include "drift/reference_blur.hpp"
#include "drift/shown_light.hpp"
#include "geometry/intersect.hpp"
#include "geometry/yaw_pitch_roll.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "textured_content.hpp"

namespace procam::drift {
namespace {

// The device turnedBy about its own centre by yaw/pitch/roll in its own frame.
geom::Pose turnedBy(const geom::Pose& pose, double yaw_deg, double pitch_deg) {
  geom::YawPitchRoll a;
  a.yaw = degToRad(yaw_deg);
  a.pitch = degToRad(pitch_deg);
  const Mat3 Q = geom::parentFromChild(a);  // the scene's events turn devices the same way
  geom::Pose p;
  p.R = Q.transpose() * pose.R;
  p.t = Q.transpose() * pose.t;
  return p;
}

struct PlanarRig {
  sim::Scene scene;
  rig::RigModel model;
  geom::PlaneHomography tile;
  geom::CameraModel camera;
};

PlanarRig restingPlanarRig() {
  auto scene = sim::resolveScene("wall_oblique");
  EXPECT_TRUE(scene) << scene.error().message;
  auto model = sim::truthRig(*scene, 0.0);
  EXPECT_TRUE(model) << model.error().message;
  auto tile = blend::displayTile(model->projectors.at(0), model->surface);
  EXPECT_TRUE(tile) << tile.error().message;
  return {*scene, *model, tile->projector_to_plane, model->cameras.at(0).model};
}

struct PlanarView {
  cv::Mat shown;   // work grid, CV_32F
  cv::Mat camera;  // CV_32F
  cv::Mat map;
  WorkGrid grid;
};

PlanarView planarViewOf(const PlanarRig& rig, const cv::Mat& framebuffer,
                        const geom::Pose& projector_pose,
                        const std::optional<geom::Pose>& camera_pose = std::nullopt) {
  sim::SceneState state = rig.scene.at(0);
  state.projectors.at(0).model.pose = projector_pose;
  if (camera_pose) state.cameras.at(0).model.pose = *camera_pose;
  auto renderer = sim::Renderer::create(rig.scene, state, {{"proj", framebuffer}});
  EXPECT_TRUE(renderer) << renderer.error().message;
  auto image = renderer->renderCamera("cam");
  EXPECT_TRUE(image) << image.error().message;
  PlanarView v;
  v.grid = {framebuffer.size(), 2};
  image->convertTo(v.camera, CV_32F);
  // The frame's light, through the projector's true response.
  auto shown = shownLight(framebuffer, rig.scene.at(0).projectors.at(0).spec.gamma, v.grid);
  EXPECT_TRUE(shown) << shown.error().message;
  if (shown) v.shown = *shown;
  auto map = projectorCameraMap(rig.tile, rig.camera, v.grid);
  EXPECT_TRUE(map) << map.error().message;
  v.map = *map;
  return v;
}

// Framebuffer pixel `p` of the projector at `pose` lands on the wall where the rig model
// (at rest) puts this framebuffer point.
Vec2 whereTheRigSees(const PlanarRig& rig, const geom::Pose& pose, const Vec2& p) {
  geom::CameraModel m = rig.scene.at(0).projectors.at(0).model;
  m.pose = pose;
  auto ray = m.backproject(p);
  auto hit = geom::intersectPlane(*ray, *rig.model.surface.plane);
  geom::CameraModel rest = rig.scene.at(0).projectors.at(0).model;
  return *rest.project(hit->point);
}

TEST(DriftCheck, AProjectorAtRestShowsNoMisregistration) {
  const PlanarRig rig = restingPlanarRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(0).model.pose;
  const PlanarView v = planarViewOf(rig, texturedContent({1920, 1080}, 3, {96, 32, 12}), rest);
  auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
  ASSERT_TRUE(m) << m.error().message;
  std::printf(
      "[ figures  ] at rest: %d tiles seen, %d textured, %d used; misregistration rms %.3f "
      "px, max %.3f px; tiles scatter %.3f px; confidence %.2f\n",
      m->tiles_seen, m->tiles_textured, m->tiles_used, m->rms_px, m->max_px, m->tile_rms_px,
      m->confidence);
  EXPECT_FALSE(m->too_plain);
  EXPECT_GE(m->tiles_used, 40);
  // A fifth of the 0.5 px the daemon acts on: no false trigger from noise.
  EXPECT_LT(m->rms_px, 0.1);
  EXPECT_LT(m->max_px, 0.1);
}

TEST(DriftCheck, PlainContentIsTooPlainToTell) {
  const PlanarRig rig = restingPlanarRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(0).model.pose;
  for (int level : {0, 128}) {
    const PlanarView v = planarViewOf(rig, cv::Mat(1080, 1920, CV_8U, cv::Scalar(level)), rest);
    auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
    ASSERT_TRUE(m) << m.error().message;
    EXPECT_TRUE(m->too_plain) << level;
    EXPECT_EQ(m->tiles_textured, 0);
    EXPECT_GT(m->tiles_seen, 40);
  }
}

// Grey bands with straight, slanted edges between them: a plain image's borders.
cv::Mat slantedBands() {
  cv::Mat bands(1080, 1920, CV_8U, cv::Scalar(40));
  for (int k = 0; k < 4; ++k) {
    const int x = 200 + 450 * k;
    const std::vector<cv::Point> band{{x, 0}, {x + 220, 0}, {x + 120, 1079}, {x - 100, 1079}};
    cv::fillConvexPoly(bands, band, cv::Scalar(200), cv::LINE_AA);
  }
  return bands;
}

// The same bands crossed by horizontal ones: sharp corners, which the camera sees blurred.
cv::Mat crossedBands() {
  cv::Mat crossed = slantedBands();
  for (int y = 150; y + 120 <= 1080; y += 300) crossed.rowRange(y, y + 120).setTo(cv::Scalar(120));
  return crossed;
}

// A plain image's border alone: grey bands with straight, slanted edges between them.
// An edge fixes no shift along itself, so its tiles are not textured and the frame is
// too plain to tell; counted as texture (no isotropy test) they are, and the same bands
// crossed by others make corners that count.
TEST(DriftCheck, EdgesAloneAreTooPlainToTell) {
  const PlanarRig rig = restingPlanarRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(0).model.pose;
  const PlanarView v = planarViewOf(rig, slantedBands(), rest);
  auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
  ASSERT_TRUE(m) << m.error().message;
  MisregistrationOptions any_edge;
  any_edge.min_isotropy = 0;
  auto counted = measureMisregistration(v.shown, v.camera, v.map, v.grid, any_edge);
  ASSERT_TRUE(counted) << counted.error().message;
  const PlanarView x = planarViewOf(rig, crossedBands(), rest);
  auto corners = measureMisregistration(x.shown, x.camera, x.map, x.grid);
  ASSERT_TRUE(corners) << corners.error().message;
  std::printf(
      "[ figures  ] edges alone: %d of %d tiles textured (%d counting edges); crossed: %d "
      "textured, %d used, misregistration %.3f px\n",
      m->tiles_textured, m->tiles_seen, counted->tiles_textured, corners->tiles_textured,
      corners->tiles_used, corners->rms_px);
  EXPECT_TRUE(m->too_plain);
  EXPECT_EQ(m->tiles_textured, 0);
  EXPECT_GE(counted->tiles_textured, 0.15 * counted->tiles_seen);
  // Where the bands cross, tiles hold corners: texture in two directions.
  EXPECT_GE(corners->tiles_textured, 8);
}

// The blur the virtual camera sees the frame with, in work pixels at the grid's centre:
// the projector's pixel footprint, the camera's lens, its pixel (a box: variance 1/12)
// and the bilinear resampling onto the grid (a tent: 1/6).
double theoreticalBlur(const PlanarRig& rig, const PlanarView& v) {
  const cv::Point c(v.map.cols / 2, v.map.rows / 2);
  const cv::Vec2f m0 = v.map.at<cv::Vec2f>(c), mx = v.map.at<cv::Vec2f>(c + cv::Point(1, 0)),
                  my = v.map.at<cv::Vec2f>(c + cv::Point(0, 1));
  const double camera_px_per_work = std::sqrt(
      std::abs(double(mx[0] - m0[0]) * (my[1] - m0[1]) - double(mx[1] - m0[1]) * (my[0] - m0[0])));
  const double s = 1.0 / camera_px_per_work;  // a camera pixel, in work pixels
  const double projector = rig.scene.at(0).projectors.at(0).spec.blur_sigma_px / v.grid.factor;
  const double lens = rig.scene.at(0).cameras.at(0).spec.psf_sigma_px;
  return std::sqrt(projector * projector + s * s * (lens * lens + 1.0 / 12 + 1.0 / 6));
}

TEST(DriftCheck, TheReferenceIsBlurredAsTheCameraSeesTheFrame) {
  const PlanarRig rig = restingPlanarRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(0).model.pose;
  for (const auto& [name, content] :
       {std::pair{"crossed bands", crossedBands()},
        std::pair{"textured", texturedContent({1920, 1080}, 3, {96, 32, 12})}}) {
    SCOPED_TRACE(name);
    const PlanarView v = planarViewOf(rig, content, rest);
    auto sharp = measureMisregistration(v.shown, v.camera, v.map, v.grid);
    auto fitted = fitReferenceBlur(v.shown, v.camera, v.map, v.grid);
    ASSERT_TRUE(sharp) << sharp.error().message;
    ASSERT_TRUE(fitted) << fitted.error().message;
    ASSERT_TRUE(fitted->sigma_px);
    const Misregistration& m = fitted->at_best;
    const double theory = theoreticalBlur(rig, v);
    std::printf(
        "[ figures  ] %s at rest: sharp reference %.3f px (tiles scatter %.3f, %d used); "
        "blurred by %.2f work px (theory %.2f) %.3f px (scatter %.3f, %d used)\n",
        name, sharp->rms_px, sharp->tile_rms_px, sharp->tiles_used, *fitted->sigma_px, theory,
        m.rms_px, m.tile_rms_px, m.tiles_used);
    // Within the candidates' spacing of what the scene's optics give.
    EXPECT_NEAR(*fitted->sigma_px, theory, 0.5);
    EXPECT_FALSE(m.too_plain);
    // Half the 0.5 px the daemon acts on (the sharp reference reads the bands 0.33 px off).
    EXPECT_LT(m.rms_px, 0.25);
    // The fit's own measure: the collineation's standard error, no worse than unblurred.
    const auto standardError = [](const Misregistration& r) {
      return r.tile_rms_px / std::sqrt(static_cast<double>(r.tiles_used));
    };
    EXPECT_LE(standardError(m), standardError(*sharp));
  }
  // Nothing to register: no blur is found, and the frame is too plain.
  const PlanarView plain = planarViewOf(rig, cv::Mat(1080, 1920, CV_8U, cv::Scalar(128)), rest);
  auto none = fitReferenceBlur(plain.shown, plain.camera, plain.map, plain.grid);
  ASSERT_TRUE(none);
  EXPECT_FALSE(none->sigma_px);
  EXPECT_TRUE(none->at_best.too_plain);
  MisregistrationOptions out_of_range;
  out_of_range.reference_blur_px = 9;
  EXPECT_EQ(measureMisregistration(plain.shown, plain.camera, plain.map, plain.grid, out_of_range)
                .error()
                .code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(
      fitReferenceBlur(plain.shown, plain.camera, plain.map, plain.grid, {}, {}, {}).error().code,
      ErrorCode::kInvalidInput);
  const double descending[] = {1.0, 0.5};
  EXPECT_EQ(fitReferenceBlur(plain.shown, plain.camera, plain.map, plain.grid, {}, {}, descending)
                .error()
                .code,
            ErrorCode::kInvalidInput);
}

TEST(DriftCheck, ABumpedProjectorIsMeasuredAndItsPoseCorrectedFromContent) {
  const PlanarRig rig = restingPlanarRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(0).model.pose;
  const cv::Mat content = texturedContent({1920, 1080}, 5, {96, 32, 12});
  for (auto [yaw, pitch] : {std::pair{0.5, 0.0}, std::pair{0.0, -2.0}, std::pair{1.2, 0.8}}) {
    SCOPED_TRACE(testing::Message() << "yaw " << yaw << " pitch " << pitch);
    const geom::Pose bumped = turnedBy(rest, yaw, pitch);
    const PlanarView v = planarViewOf(rig, content, bumped);
    auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
    ASSERT_TRUE(m) << m.error().message;
    // Each registered tile against where the bumped projector truly puts its content.
    double sq = 0, worst = 0, true_sq = 0;
    int n = 0;
    for (const TileShift& t : m->tiles) {
      if (!t.inlier) continue;
      const Vec2 truth = whereTheRigSees(rig, bumped, t.drawn);
      const double e = (truth - t.seen_at).norm();
      sq += e * e;
      true_sq += (truth - t.drawn).squaredNorm();
      worst = std::max(worst, e);
      ++n;
    }
    ASSERT_GT(n, 30);
    const double rms = std::sqrt(sq / n), true_rms = std::sqrt(true_sq / n);
    auto c = correctProjector(rig.model.projectors.at(0), rig.tile, *m);
    ASSERT_TRUE(c) << c.error().message;
    // The corrected projector against the true bumped one over the framebuffer.
    double after = 0;
    geom::CameraModel fixed = rig.scene.at(0).projectors.at(0).model;
    fixed.pose = c->projector.pose;
    geom::CameraModel truth = fixed;
    truth.pose = bumped;
    for (int y = 0; y < 1080; y += 60) {
      for (int x = 0; x < 1920; x += 60) {
        auto hit = geom::intersectPlane(*fixed.backproject({x, y}), *rig.model.surface.plane);
        ASSERT_TRUE(hit);
        after = std::max(after, (*truth.project(hit->point) - Vec2(x, y)).norm());
      }
    }
    // A projector the rig knows only by its plane collineation (route (b′)): the new
    // collineation against the same truth.
    rig::RigProjector planar = rig.model.projectors.at(0);
    planar.intrinsics_known = false;
    planar.pose_known = false;
    planar.plane_homography = rig.tile;
    auto cp = correctProjector(planar, rig.tile, *m);
    ASSERT_TRUE(cp) << cp.error().message;
    ASSERT_TRUE(cp->projector.plane_homography);
    EXPECT_EQ(cp->pose_rms_px, -1);
    double after_planar = 0;
    for (int y = 0; y < 1080; y += 60) {
      for (int x = 0; x < 1920; x += 60) {
        const geom::PlaneHomography& ph = *cp->projector.plane_homography;
        const Vec3 ab = ph.H * Vec3(x, y, 1.0);
        const Vec3 X = ph.basis.toWorld({ab.x() / ab.z(), ab.y() / ab.z()});
        after_planar = std::max(after_planar, (*truth.project(X) - Vec2(x, y)).norm());
      }
    }
    std::printf(
        "[ figures  ] bump yaw %.1f pitch %.1f deg: true shift rms %.2f px; measured "
        "%.2f px (%d tiles), per-tile error rms %.3f max %.3f px; corrected: worst "
        "%.3f px (pose fit %.3f px), plane collineation alone %.3f px\n",
        yaw, pitch, true_rms, m->rms_px, m->tiles_used, rms, worst, after, c->pose_rms_px,
        after_planar);
    EXPECT_NEAR(m->rms_px, true_rms, 0.01 * true_rms + 0.1);
    // Each tile alone within 0.3 px (below the 0.5 px the daemon acts on); the corrected
    // projector within half the 0.5 px a corrected rig must reach.
    EXPECT_LT(rms, 0.3);
    EXPECT_LT(after, 0.25);
    EXPECT_LT(after_planar, 0.25);
  }
}

TEST(DriftCheck, ABumpedCameraIsReregisteredFromTheContent) {
  const PlanarRig rig = restingPlanarRig();
  const geom::Pose rest = rig.scene.at(0).projectors.at(0).model.pose;
  const cv::Mat content = texturedContent({1920, 1080}, 7, {96, 32, 12});
  for (auto [yaw, pitch] : {std::pair{0.3, 0.0}, std::pair{-0.2, 0.4}}) {
    SCOPED_TRACE(testing::Message() << "camera yaw " << yaw << " pitch " << pitch);
    geom::CameraModel truth = rig.camera;
    truth.pose = turnedBy(rig.camera.pose, yaw, pitch);
    const PlanarView v = planarViewOf(rig, content, rest, truth.pose);
    auto m = measureMisregistration(v.shown, v.camera, v.map, v.grid);
    ASSERT_TRUE(m) << m.error().message;
    auto c = correctCamera(rig.model.cameras.at(0), rig.tile, *m, v.map, v.grid);
    ASSERT_TRUE(c) << c.error().message;
    // The corrected camera against the true bumped one over the wall it sees.
    double worst = 0;
    int n = 0;
    for (int y = 0; y < truth.height; y += 40) {
      for (int x = 0; x < truth.width; x += 40) {
        auto hit = geom::intersectPlane(*truth.backproject({x, y}), *rig.model.surface.plane);
        if (!hit) continue;
        auto back = c->camera.model.project(hit->point);
        ASSERT_TRUE(back);
        worst = std::max(worst, (*back - Vec2(x, y)).norm());
        ++n;
      }
    }
    ASSERT_GT(n, 100);
    std::printf(
        "[ figures  ] camera bumped yaw %.1f pitch %.1f deg: content moved %.2f px in the "
        "projector's frame; camera refit %.3f px RMS over %d tiles, against the true "
        "camera %.3f camera px at worst\n",
        yaw, pitch, m->rms_px, c->pose_rms_px, c->tiles, worst);
    // A camera pixel is about 2.5 projector pixels on this wall: within the 0.5 px
    // registration bound the corrected rig is held to.
    EXPECT_LT(worst, 0.2);
  }
}

// The reference is light: code 128 of a gamma-2.2 projector is 255 (128/255)^2.2 = 56.0
// of full white's 255, in grey and through the luminance of an RGBA frame alike.
TEST(DriftCheck, TheReferenceIsTheFramesLight) {
  const WorkGrid grid{{64, 32}, 2};
  auto grey = shownLight(cv::Mat(32, 64, CV_8UC1, cv::Scalar(128)), 2.2, grid);
  ASSERT_TRUE(grey) << grey.error().message;
  ASSERT_EQ(grey->size(), grid.size());
  EXPECT_NEAR(grey->at<float>(5, 5), 255 * std::pow(128 / 255.0, 2.2), 1e-3);
  auto rgba = shownLight(cv::Mat(32, 64, CV_8UC4, cv::Scalar(128, 128, 128, 255)), 2.2, grid);
  ASSERT_TRUE(rgba) << rgba.error().message;
  EXPECT_NEAR(rgba->at<float>(5, 5), grey->at<float>(5, 5), 1e-3);
  EXPECT_EQ(shownLight(cv::Mat(32, 64, CV_8UC1), 0.5, grid).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(shownLight(cv::Mat(32, 64, CV_8UC3), 2.2, grid).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(shownLight(cv::Mat(30, 64, CV_8UC1), 2.2, grid).error().code, ErrorCode::kInvalidInput);
}

TEST(DriftCheck, MismatchedInputIsRefused) {
  WorkGrid grid{{64, 64}, 2};
  cv::Mat shown(32, 32, CV_32F, cv::Scalar(0)), camera(10, 10, CV_32F, cv::Scalar(0));
  cv::Mat map(31, 32, CV_32FC2, cv::Scalar(-1, -1));
  EXPECT_EQ(measureMisregistration(shown, camera, map, grid).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(projectorCameraMap(geom::PlaneHomography{}, {}, WorkGrid{{64, 64}, 0}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(projectorCameraMap(LitSurface{}, {}, grid).error().code, ErrorCode::kInvalidInput);
  Misregistration few;
  EXPECT_EQ(correctProjector({}, geom::PlaneHomography{}, few).error().code,
            ErrorCode::kTooFewPoints);
  // On a mesh the projector's pose is what is corrected: none, nothing to correct.
  EXPECT_EQ(correctProjector({}, LitSurface{}, few).error().code, ErrorCode::kInvalidInput);
  rig::RigCamera posed;
  EXPECT_EQ(correctCamera(posed, geom::PlaneHomography{}, few, map, grid).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(correctCamera(posed, LitSurface{}, few, map, grid).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::drift
