// Calibration accuracy on the virtual rig under the reference capture conditions:
// camera read noise 1 DN on 8-bit captures, projector gamma 2.2, ambient light 10% of
// the white level. The
// shipped scenes are used at half resolution (intrinsics scaled) to keep the
// rendering to seconds; tolerances are procamd's calibration accuracy bounds.
#include <gtest/gtest.h>

#include "calibration/projector_calibration.hpp"
#include "calibration/stereo_route.hpp"
#include "geometry/intersect.hpp"
#include "issue_scenes.hpp"
#include "route_tolerances.hpp"
#include "structured_light/decoder.hpp"
#include "surface/projector_samples.hpp"
#include "surface/stereo_points.hpp"
#include "surface/surface_model.hpp"

using namespace procam;
using procam::testing::expectMatches;
using procam::testing::rotationErrorDeg;

namespace {

std::string cornerStereo() {
  std::string t = procam::testing::issueCornerStereo();
  EXPECT_FALSE(t.empty());
  return t;
}

std::string wallOblique(double wall_yaw_deg) {
  std::string t = procam::testing::issueWallOblique(wall_yaw_deg);
  EXPECT_FALSE(t.empty());
  return t;
}

sim::Scene parse(const std::string& text) {
  auto s = sim::Scene::parse(text, "test scene", {});
  EXPECT_TRUE(s) << s.error().message;
  return std::move(*s);
}

// Gray + 8-phase captures of both corner_stereo cameras, rendered once per run.
const std::map<std::string, std::vector<cv::Mat>>& cornerPhaseCaptures(const sim::Scene& scene,
                                                                       const sl::PatternSet& set) {
  static const auto captures = [&] {
    auto c = procam::testing::capture(scene, set, 11);
    EXPECT_TRUE(c) << c.error().message;
    return c ? *c : std::map<std::string, std::vector<cv::Mat>>{};
  }();
  return captures;
}

sl::PatternSet cornerPhaseSet() {
  return *sl::makePatternSet(
      {.width = 640, .height = 400, .mode = sl::Mode::kGrayPhase, .phase_steps = 8});
}

struct AxisError {
  double rms = 0;
  int pixels = 0;  // decoded and lit
  int lit = 0;     // lit in the camera's view
};

// Decoded u, v against the true projector pixel of every lit, decoded camera pixel.
AxisError correspondenceError(const sim::Scene& scene, const std::string& camera,
                              const sl::Decoded& d) {
  auto r = sim::Renderer::create(scene, scene.at(0), {});
  auto truth = r->cameraTruth(camera);
  EXPECT_TRUE(truth);
  double sum = 0;
  AxisError e;
  e.lit = cv::countNonZero(truth->lit[0]);
  for (int y = 0; y < d.u.rows; ++y)
    for (int x = 0; x < d.u.cols; ++x) {
      if (d.flags.at<std::uint8_t>(y, x) != 0 || truth->lit[0].at<std::uint8_t>(y, x) == 0)
        continue;
      const cv::Vec2f p = truth->projector_pixel[0].at<cv::Vec2f>(y, x);
      const double du = d.u.at<float>(y, x) - p[0], dv = d.v.at<float>(y, x) - p[1];
      sum += du * du + dv * dv;
      ++e.pixels;
    }
  e.rms = std::sqrt(sum / (2.0 * std::max(1, e.pixels)));
  return e;
}

}  // namespace

TEST(RigAccuracy, SignalLevelsAreTheIssues) {
  const sim::Scene scene = parse(cornerStereo());
  const sim::SceneState state = scene.at(0);
  cv::Mat white(400, 640, CV_8UC1, cv::Scalar(255)), black(400, 640, CV_8UC1, cv::Scalar(0));
  auto rw = sim::Renderer::create(scene, state, {{"proj", white}});
  auto rb = sim::Renderer::create(scene, state, {{"proj", black}});
  auto w = rw->renderCamera("cam_left", {.noise = false});
  auto b = rb->renderCamera("cam_left", {.noise = false});
  ASSERT_TRUE(w && b);
  // Back wall in the middle of the left camera's view.
  const cv::Rect centre(200, 150, 40, 40);
  const double white_level = cv::mean((*w)(centre))[0], black_level = cv::mean((*b)(centre))[0];
  EXPECT_GT(white_level, 150);
  EXPECT_LT(white_level, 250);
  EXPECT_NEAR(black_level / white_level, 0.1, 0.03);
}

// Gray alone <= 0.5 px, Gray + N-step phase <= 0.1 px for N = 3 and 8.
TEST(RigAccuracy, CorrespondencesGrayAndGrayPhase) {
  const sim::Scene scene = parse(cornerStereo());
  for (int steps : {0, 3, 8}) {
    const bool phase = steps > 0;
    const std::string what = phase ? "gray+" + std::to_string(steps) + "phase" : "gray";
    const sl::PatternSet set =
        steps == 8 ? cornerPhaseSet()
                   : *sl::makePatternSet({.width = 640,
                                          .height = 400,
                                          .mode = phase ? sl::Mode::kGrayPhase : sl::Mode::kGray,
                                          .phase_steps = std::max(steps, 3)});
    std::vector<cv::Mat> left;
    if (steps == 8) {
      left = cornerPhaseCaptures(scene, set).at("cam_left");
    } else {
      auto captures = procam::testing::capture(scene, set, 3 + steps, {"cam_left"});
      ASSERT_TRUE(captures) << captures.error().message;
      left = captures->at("cam_left");
    }
    auto d = sl::decode(set, left);
    ASSERT_TRUE(d);
    const AxisError e = correspondenceError(scene, "cam_left", *d);
    // A camera pixel here spans about two projector pixels, so the finest Gray stripes
    // are blurred away at many pixels, which the decoder then refuses (low contrast).
    EXPECT_GT(e.pixels, (phase ? 0.9 : 0.5) * e.lit) << what;
    EXPECT_LE(e.rms, phase ? 0.1 : 0.5) << what;
    std::printf(
        "[ figures  ] %s: %.4f projector px RMS per axis over %d of %d lit pixels (camera "
        "response exponent %.3f)\n",
        what.c_str(), e.rms, e.pixels, e.lit, d->response_gamma);
  }
}

namespace {

surface::ProjectorSamples samples(const sl::PatternSet& set, const std::vector<cv::Mat>& captures,
                                  int step) {
  auto d = sl::decode(set, captures);
  EXPECT_TRUE(d);
  auto s = surface::sampleProjectorGrid(*d, set.options.width, set.options.height, {.step = step});
  EXPECT_TRUE(s);
  return std::move(*s);
}

}  // namespace

// corner_stereo, route (a): focal 0.5%, principal point 2 px, position 2 mm,
// rotation 0.05 degrees, reprojection RMS <= 0.15 px; surface <= 1 mm RMS.
TEST(RigAccuracy, CornerStereoRouteA) {
  const sim::Scene scene = parse(cornerStereo());
  const sim::SceneState state = scene.at(0);
  const sl::PatternSet phase_set = cornerPhaseSet();
  const sl::PatternSet* set = &phase_set;
  const auto* captures = &cornerPhaseCaptures(scene, phase_set);
  ASSERT_EQ(captures->size(), 2u);
  const auto& left = state.camera("cam_left")->model;
  const auto& right = state.camera("cam_right")->model;
  auto points = surface::triangulateStereo(left, samples(*set, captures->at("cam_left"), 4), right,
                                           samples(*set, captures->at("cam_right"), 4));
  ASSERT_TRUE(points) << points.error().message;
  ASSERT_GT(points->world.size(), 3000u);

  auto c = calib::calibrateProjectorFromSurface(*points);
  ASSERT_TRUE(c) << c.error().message;
  const geom::CameraModel& truth = state.projectors[0].model;
  expectMatches(*c, truth);
  EXPECT_LE(c->rms_px, 0.15);

  // The walls: y = 3 (x <= 0) and x = 0 (y <= 3), against the points consistent
  // with the calibrated projector.
  const surface::SurfacePoints kept = surface::keepPoints(*points, c->inliers);
  EXPECT_GT(kept.world.size(), 0.9 * points->world.size());
  double sum = 0;
  for (const Vec3& x : kept.world) {
    const double d = std::min(std::abs(x.y() - 3.0), std::abs(x.x()));
    sum += d * d;
  }
  const double surface_rms = std::sqrt(sum / kept.world.size());
  auto model = surface::buildSurface(kept);
  ASSERT_TRUE(model);
  EXPECT_FALSE(model->planar);
  EXPECT_GT(model->mesh.faces.size(), 10u);
  std::printf(
      "[ figures  ] route a: fx %.2f (%.2f) fy %.2f (%.2f) cx %.2f (%.2f) cy %.2f (%.2f), "
      "centre error %.2f mm, rotation error %.4f deg, rms %.3f px, surface %.3f mm RMS over %zu "
      "points\n",
      c->K.fx, truth.K.fx, c->K.fy, truth.K.fy, c->K.cx, truth.K.cx, c->K.cy, truth.K.cy,
      1000 * (c->pose.center() - truth.pose.center()).norm(),
      rotationErrorDeg(c->pose.R, truth.pose.R), c->rms_px, 1000 * surface_rms, kept.world.size());
}

// wall_oblique: route (a) returns the coplanar error; route (b) with two wall
// orientations meets the intrinsics tolerances (focal 0.5%, principal point 2 px).
TEST(RigAccuracy, WallObliqueCoplanarAndRouteB) {
  auto set = sl::makePatternSet(
      {.width = 960, .height = 540, .mode = sl::Mode::kGrayPhase, .phase_steps = 8});
  ASSERT_TRUE(set);
  std::vector<calib::PlaneView> views;
  geom::CameraModel camera, projector;
  double first_distance = 0;
  for (double yaw : {0.0, 25.0}) {
    const sim::Scene scene = parse(wallOblique(yaw));
    const sim::SceneState state = scene.at(0);
    camera = state.camera("cam")->model;
    projector = state.projectors[0].model;
    auto captures = procam::testing::capture(
        scene, *set, 20 + static_cast<int>(yaw),
        yaw == 0.0 ? std::vector<std::string>{"cam", "cam2"} : std::vector<std::string>{"cam"});
    ASSERT_TRUE(captures) << captures.error().message;
    const auto s = samples(*set, captures->at("cam"), 4);
    views.push_back({s.camera, s.projector});
    if (yaw == 0.0) {
      first_distance = std::abs(3.0 - camera.pose.center().y());  // wall y = 3 faces the camera
      auto points = surface::triangulateStereo(camera, s, state.camera("cam2")->model,
                                               samples(*set, captures->at("cam2"), 4));
      ASSERT_TRUE(points) << points.error().message;
      auto a = calib::calibrateProjectorFromSurface(*points);
      ASSERT_FALSE(a);
      EXPECT_EQ(a.error().code, ErrorCode::kCoplanar);
    }
  }
  calib::PlaneRouteOptions o;
  o.projector_width = projector.width;
  o.projector_height = projector.height;
  o.first_plane_distance = first_distance;
  auto c = calib::calibrateProjectorFromPlanes(camera, views, o);
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_NEAR(c->K.fx, projector.K.fx, 0.005 * projector.K.fx);
  EXPECT_NEAR(c->K.fy, projector.K.fy, 0.005 * projector.K.fy);
  EXPECT_NEAR(c->K.cx, projector.K.cx, 2.0);
  EXPECT_NEAR(c->K.cy, projector.K.cy, 2.0);
  std::printf(
      "[ figures  ] route b: f %.2f (%.2f) cy %.2f (%.2f), centre error %.2f mm, rotation error "
      "%.4f deg, "
      "rms %.3f px\n",
      c->K.fx, projector.K.fx, c->K.cy, projector.K.cy,
      1000 * (c->pose.center() - projector.pose.center()).norm(),
      rotationErrorDeg(c->pose.R, projector.pose.R), c->rms_px);
}

// A calibrated projector and one camera measure a wall the projector lights: the coarse
// Gray pass of a drift correction (one code per 8 projector pixels, nodes every 16), the
// projector's ray and the camera's through each node triangulated, one plane fitted. The
// wall stands 1 cm behind where the rig had it (y = 3.01), turned 2 degrees. Bound: the
// projector's pixels land within 0.5 px of where the true wall puts them (a drift
// correction's registration bound).
TEST(RigAccuracy, WallFromTheProjectorAndOneCameraWithGrayAlone) {
  std::string text = wallOblique(2.0);
  ASSERT_TRUE(procam::testing::edit(text, "center = [0.0, 3.0, 1.5]", "center = [0.0, 3.01, 1.5]"));
  const sim::Scene scene = parse(text);
  const sim::SceneState state = scene.at(0);
  const geom::CameraModel projector = state.projectors[0].model;
  auto set = sl::makePatternSet(
      {.width = projector.width, .height = projector.height, .mode = sl::Mode::kGray, .step = 8});
  ASSERT_TRUE(set);
  auto captures = procam::testing::capture(scene, *set, 41, {"cam"});
  ASSERT_TRUE(captures) << captures.error().message;
  auto d = sl::decode(*set, captures->at("cam"));
  ASSERT_TRUE(d) << d.error().message;
  const calib::DecodedView view{"cam", state.camera("cam")->model, std::move(*d)};
  auto nodes = calib::triangulateWithProjector(*set, projector, view, 16);
  ASSERT_TRUE(nodes) << nodes.error().message;
  auto fit = calib::triangulatedPlane(*nodes);
  ASSERT_TRUE(fit) << fit.error().message;
  const double a = 2.0 * M_PI / 180;
  const Vec3 normal(std::sin(a), -std::cos(a), 0.0);
  const geom::Plane truth{normal, -normal.dot(Vec3(0.0, 3.01, 1.5))};
  const double turned_deg =
      std::acos(std::min(1.0, std::abs(fit->plane.n.dot(truth.n)))) * 180 / M_PI;
  double worst_px = 0;
  for (int y = 0; y < projector.height; y += 30) {
    for (int x = 0; x < projector.width; x += 30) {
      auto ray = projector.backproject({x, y});
      auto next = projector.backproject({x + 1, y});
      ASSERT_TRUE(ray && next);
      auto on_true = geom::intersectPlane(*ray, truth);
      auto next_true = geom::intersectPlane(*next, truth);
      auto on_fit = geom::intersectPlane(*ray, fit->plane);
      ASSERT_TRUE(on_true && next_true && on_fit);
      const double pixel = (next_true->point - on_true->point).norm();
      worst_px = std::max(worst_px, (on_fit->point - on_true->point).norm() / pixel);
    }
  }
  std::printf(
      "[ figures  ] wall from the projector and one camera (Gray, step 8): %zu nodes, plane "
      "%.3f mm from the true one at its centre, turned %.4f deg; the projector's pixels land "
      "%.3f px at most from where the true wall puts them\n",
      nodes->world.size(), 1e3 * std::abs(fit->plane.signedDistance(Vec3(0.0, 3.01, 1.5))),
      turned_deg, worst_px);
  EXPECT_LE(worst_px, 0.5);
}

// The projector at its full 1280x800 and the cameras at 1/2 and 1/4 of 1024x768: one
// camera pixel spans ~3.3 and ~6.6 projector pixels, so neighbouring camera pixels
// decode several projector pixels apart. Route (a) as shipped (Gray + 3-phase, nodes
// every 8 projector pixels) with route (a)'s accuracy bounds: focal 0.5%, principal point
// 2 px, position 2 mm, rotation 0.05 degrees, reprojection RMS <= 0.15 px. Most lit
// pixels must decode (a neighbour test in projector pixels would drop them all).
TEST(RigAccuracy, CornerStereoRouteACoarseCameras) {
  for (const double camera_scale : {0.5, 0.25}) {
    const sim::Scene scene = parse(procam::testing::issueCornerStereo(1.0, camera_scale));
    const sim::SceneState state = scene.at(0);
    const sl::PatternSet set = *sl::makePatternSet(
        {.width = 1280, .height = 800, .mode = sl::Mode::kGrayPhase, .phase_steps = 3});
    auto captures = procam::testing::capture(scene, set, 31);
    ASSERT_TRUE(captures) << captures.error().message;
    calib::DecodedView views[2];
    const char* names[2] = {"cam_left", "cam_right"};
    for (int i = 0; i < 2; ++i) {
      auto d = sl::decode(set, captures->at(names[i]));
      ASSERT_TRUE(d);
      const AxisError e = correspondenceError(scene, names[i], *d);
      EXPECT_GT(e.pixels, 0.9 * e.lit) << names[i] << " at " << camera_scale;
      // Gray + phase <= 0.1 projector px (the decoding bound) where a camera pixel spans
      // ~3 projector pixels; at 1/4 the camera's own noise spans twice the
      // projector pixels, so 0.2.
      EXPECT_LE(e.rms, camera_scale == 0.5 ? 0.1 : 0.2) << names[i] << " at " << camera_scale;
      std::printf("[ figures  ] cameras x%.3f, %s: %.4f projector px RMS over %d of %d lit\n",
                  camera_scale, names[i], e.rms, e.pixels, e.lit);
      views[i] = {names[i], state.camera(names[i])->model, std::move(*d)};
    }
    auto r = calib::solveStereoRoute(set, views[0], views[1], 8);
    ASSERT_TRUE(r) << r.error().message;
    const calib::ProjectorCalibration& c = r->projector;
    const geom::CameraModel& truth = state.projectors[0].model;
    EXPECT_GT(r->triangulated, 10000u);
    expectMatches(c, truth);
    EXPECT_LE(c.rms_px, 0.15);
    std::printf(
        "[ figures  ] cameras x%.3f route a: %zu nodes, fx %.2f fy %.2f cx %.2f cy %.2f (truth "
        "%.2f %.2f %.2f %.2f), centre error %.2f mm, rotation error %.4f deg, rms %.3f px\n",
        camera_scale, r->triangulated, c.K.fx, c.K.fy, c.K.cx, c.K.cy, truth.K.fx, truth.K.fy,
        truth.K.cx, truth.K.cy, 1000 * (c.pose.center() - truth.pose.center()).norm(),
        rotationErrorDeg(c.pose.R, truth.pose.R), c.rms_px);
  }
}

// Gray code alone, projector 1280x800, cameras 512x384: a camera pixel spans ~3.3
// projector pixels, so the finest one or two Gray bits (stripes of 1 and 2 cells)
// blur out and the oblique left camera decodes to blocks of 2 or 4 cells. Most lit
// pixels still decode; the error is bounded by the uniform error over a block of 4,
// 4 / sqrt(12) = 1.15 projector px RMS, not the Gray-code bound of 0.5 (which needs a camera
// pixel no wider than a cell).
TEST(RigAccuracy, GrayAloneCoarseCameraDecodesToBlocks) {
  const sim::Scene scene = parse(procam::testing::issueCornerStereo(1.0, 0.5));
  const sl::PatternSet set =
      *sl::makePatternSet({.width = 1280, .height = 800, .mode = sl::Mode::kGray});
  auto captures = procam::testing::capture(scene, set, 37, {"cam_left"});
  ASSERT_TRUE(captures) << captures.error().message;
  auto d = sl::decode(set, captures->at("cam_left"));
  ASSERT_TRUE(d);
  const AxisError e = correspondenceError(scene, "cam_left", *d);
  EXPECT_GT(e.pixels, 0.9 * e.lit);
  EXPECT_LE(e.rms, 4 / std::sqrt(12.0));
  std::printf("[ figures  ] gray, cameras x0.5: %.4f projector px RMS over %d of %d lit\n", e.rms,
              e.pixels, e.lit);
}
