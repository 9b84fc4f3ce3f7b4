// procam-render on a curved rig: cylinder3's three projectors from the scene's true rig
// model (each with its true response and brightness across its frame as its photometric
// record) and the true wall as
// the surface mesh beside rig.json, drawn for the scene's viewer at the sweet spot:
//  - geometry: a 16-bit content ramp drawn geometry-only, every framebuffer pixel's code
//    read back as a content coordinate and compared with where the viewer's pinhole
//    (display.json viewer_matrix) sees the TRUE wall point the TRUE projector lights;
//  - light: the 8-bit blended frames lighting the scene, white content seen by the
//    viewer in linear light: no step above 2 % between neighbouring viewer pixels;
//  - the MPCDI 2D export read back rebuilds the 16-bit frames within 0.5 code values;
//  - what a curved rig cannot do (a wall rectangle, no viewer): refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "content_ramp.hpp"
#include "curved_display_checks.hpp"
#include "cylinder_mesh.hpp"
#include "daemon_harness.hpp"
#include "json_matrix.hpp"
#include "mpcdi_readback.hpp"
#include "render/dome_master.hpp"
#include "render_command.hpp"
#include "rig/rig_model.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "true_brightness.hpp"

namespace procam::itest {
namespace {

constexpr int kPanoramaW = 4800, kPanoramaH = 900;  // a panorama

struct CylinderRig {
  sim::Scene scene;
  sim::SceneState state;
  std::string file;
  std::string eye;  // --viewer
};

CylinderRig trueCylinder(const TempDir& dir) {
  auto scene = sim::resolveScene("cylinder3");
  EXPECT_TRUE(scene);
  CylinderRig r{*scene, scene->at(0), "", ""};
  auto rig = sim::truthRig(r.scene, 0.0);
  EXPECT_TRUE(rig);
  addTruePhotometry(r.scene, r.state, *rig);
  rig->surface = {};
  rig->surface.unified_mesh = "wall.ply";
  rig->viewer = {};
  dir.write("wall.ply", cylinderPly());
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  r.file = dir.file("rig.json");
  const Vec3 e = r.state.viewer.pose.center();
  r.eye = std::to_string(e.x()) + "," + std::to_string(e.y()) + "," + std::to_string(e.z());
  return r;
}

// Every 7th pixel of every projector's 16-bit frame in `frames`, with the TRUE wall
// point the TRUE projector lights there: expected(point) gives the content pixel it
// should show (nullopt: none), added to `error`.
template <typename Expected>
void rampAgainstTheTrueWall(const CylinderRig& rig, const TempDir& dir, Expected expected,
                            RampError& error) {
  for (const auto& p : rig.state.projectors) {
    const cv::Mat frame =
        cv::imread(dir.file("frames/" + p.spec.name + ".png"), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(frame.type(), CV_16UC3) << p.spec.name;
    const Mat34 P = p.model.projectionMatrix();
    const Mat3 Minv = P.leftCols<3>().inverse();
    const Vec3 C = -Minv * P.col(3);
    for (int y = 2; y < frame.rows; y += 7) {
      for (int x = 2; x < frame.cols; x += 7) {
        const auto hit = rig.scene.world().intersect({C, (Minv * Vec3(x, y, 1)).normalized()});
        if (!hit) continue;
        const cv::Vec3w code = frame.at<cv::Vec3w>(y, x);
        if (const auto c = expected(hit->hit.point, code)) error.add(code, *c);
      }
    }
  }
}

TEST(RenderCliCurved, FramebuffersShowTheViewerEveryContentPixelWhereTheTrueRigPutsIt) {
  TempDir dir;
  const CylinderRig rig = trueCylinder(dir);
  const cv::Mat ramp = contentRamp(kPanoramaW, kPanoramaH);
  ASSERT_TRUE(cv::imwrite(dir.file("ramp.png"), ramp));
  auto args = render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("ramp.png"),
                                           "--out", dir.file("frames"), "--viewer", rig.eye,
                                           "--bit-depth", "16", "--geometry-only"});
  ASSERT_TRUE(args) << args.error().message;
  auto doc = render_cli::runRender(*args);
  ASSERT_TRUE(doc) << doc.error().message;
  ASSERT_EQ((*doc)["projectors"].size(), 3u) << doc->dump();
  EXPECT_EQ((*doc)["display"]["surface"], "mesh");
  EXPECT_EQ((*doc)["display"]["viewer"]["source"], "given");
  const Mat34 V = rowMajor34((*doc)["display"]["viewer_matrix"]);
  RampError error{kPanoramaW, kPanoramaH};
  for (const json& share : (*doc)["projectors"]) EXPECT_EQ(share["path"], "lookup-warp");
  rampAgainstTheTrueWall(
      rig, dir,
      [&](const Vec3& X, const cv::Vec3w&) -> std::optional<Vec2> {
        const Vec2 c = (V * X.homogeneous()).hnormalized();
        // Inside the content, one pixel in from its edge (the edge half pixel is clamped).
        if (c.x() < 1 || c.y() < 1 || c.x() > kPanoramaW - 2 || c.y() > kPanoramaH - 2)
          return std::nullopt;
        return c;
      },
      error);
  ASSERT_GT(error.n, 10000);
  std::printf(
      "[ figures  ] procam-render, curved: %ld framebuffer pixels, content position error RMS "
      "%.4f px, max %.4f px\n",
      error.n, error.rms(), error.worst);
  // The lookup warp's interpolation between nodes 8 px apart (under 0.05 content px on
  // this wall) and 16-bit codes (1/14 content px across 4800).
  EXPECT_LT(error.rms(), 0.05);
  EXPECT_LT(error.worst, 0.1);
}

// The same rig drawn as a dome master around the viewer (--dome): 240 degrees across
// its circle, the front +Y at its bottom, so that the wall around the eye's horizon is
// inside it. Every framebuffer pixel shows the content pixel of the direction from the
// eye to the TRUE wall point the TRUE projector lights (render/dome_master.hpp).
TEST(RenderCliCurved, ADomeMasterShowsEachDirectionWhereItsFisheyePutsIt) {
  TempDir dir;
  const CylinderRig rig = trueCylinder(dir);
  constexpr int kSide = 2048;
  ASSERT_TRUE(cv::imwrite(dir.file("ramp.png"), contentRamp(kSide, kSide)));
  auto args =
      render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("ramp.png"), "--out",
                                   dir.file("frames"), "--viewer", rig.eye, "--dome", "0,1,0",
                                   "--dome-fov", "240", "--bit-depth", "16", "--geometry-only"});
  ASSERT_TRUE(args) << args.error().message;
  auto doc = render_cli::runRender(*args);
  ASSERT_TRUE(doc) << doc.error().message;
  ASSERT_EQ((*doc)["projectors"].size(), 3u) << doc->dump();
  EXPECT_EQ((*doc)["display"]["projection"], "dome");
  EXPECT_EQ((*doc)["display"]["dome"]["fov_deg"], 240.0);
  EXPECT_FALSE((*doc)["display"].contains("viewer_matrix"));
  const double coverage = (*doc)["display"]["dome"]["coverage"].get<double>();
  EXPECT_GT(coverage, 0.0);
  EXPECT_LT(coverage, 1.0);
  auto master =
      render::domeMaster(rig.state.viewer.pose.center(), Vec3(0, 1, 0), 240, {kSide, kSide});
  ASSERT_TRUE(master);
  RampError error{kSide, kSide};
  rampAgainstTheTrueWall(
      rig, dir,
      [&](const Vec3& X, const cv::Vec3w& code) -> std::optional<Vec2> {
        if (code[2] == 0) return std::nullopt;  // outside the drawn circle: black
        return master->contentPixel(X);
      },
      error);
  ASSERT_GT(error.n, 10000);
  std::printf(
      "[ figures  ] procam-render, dome master: %ld framebuffer pixels, content position "
      "error RMS %.4f px, max %.4f px; %.1f %% of the circle drawn\n",
      error.n, error.rms(), error.worst, 100 * coverage);
  // As the perspective display's: the lookup's interpolation between nodes 8 px apart
  // and 16-bit codes (1/32 content px across 2048).
  EXPECT_LT(error.rms(), 0.05);
  EXPECT_LT(error.worst, 0.1);

  // A vertical front is refused.
  auto bad = render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("ramp.png"),
                                          "--out", dir.file("frames"), "--dome", "0,0,1"});
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("--dome"), std::string::npos) << bad.error().message;
  // So is a field without a dome master to give it to.
  auto lone = render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("ramp.png"),
                                           "--out", dir.file("frames"), "--dome-fov", "200"});
  ASSERT_FALSE(lone);
  EXPECT_NE(lone.error().message.find("give --dome"), std::string::npos) << lone.error().message;
}

TEST(RenderCliCurved, BlendedFramesLightTheCurvedWallEvenlyForTheViewer) {
  TempDir dir;
  const CylinderRig rig = trueCylinder(dir);
  ASSERT_TRUE(cv::imwrite(dir.file("white.png"),
                          cv::Mat(kPanoramaH, kPanoramaW, CV_8UC3, cv::Scalar::all(255))));
  auto doc = render_cli::runRender(
      *render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("white.png"), "--out",
                                    dir.file("frames"), "--viewer", rig.eye}));
  ASSERT_TRUE(doc) << doc.error().message;
  EXPECT_EQ((*doc)["blend"]["response"], "measured");
  const json& matching = (*doc)["blend"]["photometric"];
  EXPECT_EQ(matching["matching"], "per-pixel") << matching.dump();
  const Mat34 V = rowMajor34((*doc)["display"]["viewer_matrix"]);
  sim::Framebuffers shown;
  for (const auto& p : rig.state.projectors) {
    shown[p.spec.name] = cv::imread(dir.file("frames/" + p.spec.name + ".png"));
    ASSERT_FALSE(shown[p.spec.name].empty());
  }
  auto lit = sim::Renderer::create(rig.scene, rig.state, shown);
  ASSERT_TRUE(lit);
  const cv::Mat view = lit->renderViewer(4);
  auto inside = [&](int x, int y) {
    auto ray = rig.state.viewer.backproject(Vec2(x, y));
    if (!ray) return false;
    auto hit = rig.scene.world().intersect(*ray);
    if (!hit) return false;
    const Vec2 q = (V * hit->hit.point.homogeneous()).hnormalized();
    return q.x() > 0.03 * kPanoramaW && q.x() < 0.97 * kPanoramaW && q.y() > 0.03 * kPanoramaH &&
           q.y() < 0.97 * kPanoramaH;
  };
  const ViewerLight light = viewerLight(view, inside);
  EXPECT_FALSE(light.unlit) << "an unlit point inside the display at viewer pixel "
                            << light.unlit->transpose();
  std::printf(
      "[ figures  ] procam-render, curved: white seen by the viewer, %ld pixels, "
      "largest step %.2f %%, uniformity min/max %.3f (matching: %s)\n",
      light.pixels, 100 * light.step, light.uniformity(), matching.dump().c_str());
  EXPECT_GT(light.pixels, 20000);
  EXPECT_LE(light.step, 0.02);
}

TEST(RenderCliCurved, MpcdiPackageRebuildsTheSameFramebuffers) {
  TempDir dir;
  const CylinderRig rig = trueCylinder(dir);
  cv::Mat content(300, 1600, CV_8UC3);
  for (int y = 0; y < content.rows; ++y) {
    for (int x = 0; x < content.cols; ++x) {
      content.at<cv::Vec3b>(y, x) = {uint8_t(x * 255 / 1599), uint8_t(y * 255 / 299),
                                     uint8_t(128 + 100 * std::sin(x * 0.05) * std::cos(y * 0.07))};
    }
  }
  ASSERT_TRUE(cv::imwrite(dir.file("slide.png"), content));
  const std::string package = dir.file("cylinder.mpcdi");
  auto doc = render_cli::runRender(*render_cli::parseRenderArgs(
      {"--rig", rig.file, "--content", dir.file("slide.png"), "--out", dir.file("frames"),
       "--viewer", rig.eye, "--bit-depth", "16", "--mpcdi", package}));
  ASSERT_TRUE(doc) << doc.error().message;
  EXPECT_EQ((*doc)["mpcdi"], package);
  const double worst = mpcdiDifference(package, dir.file("frames"), content, 3);
  std::printf(
      "[ figures  ] MPCDI of the curved display read back: largest difference from "
      "procam-render's frames %.4f 8-bit code values\n",
      worst);
  EXPECT_GE(worst, 0);
  EXPECT_LE(worst, 0.5);
}

TEST(RenderCliCurved, WhatACurvedRigCannotDoIsRefusedWithAReason) {
  TempDir dir;
  const CylinderRig rig = trueCylinder(dir);
  ASSERT_TRUE(cv::imwrite(dir.file("white.png"), cv::Mat(90, 480, CV_8UC3, cv::Scalar::all(255))));
  auto refused = [&](std::vector<std::string> extra, const std::string& says) {
    std::vector<std::string> a = {"--rig", rig.file,           "--content", dir.file("white.png"),
                                  "--out", dir.file("refused")};
    a.insert(a.end(), extra.begin(), extra.end());
    auto args = render_cli::parseRenderArgs(a);
    ASSERT_TRUE(args) << args.error().message;
    auto doc = render_cli::runRender(*args);
    ASSERT_FALSE(doc) << says;
    EXPECT_NE(doc.error().message.find(says), std::string::npos) << doc.error().message;
  };
  refused({}, "--viewer");  // the rig names no viewer
  refused({"--viewer", rig.eye, "--rect", "0,3,1.6,2,1"}, "planar display");
  refused({"--viewer", "0,2.5,1.6"}, "behind the eye");
  EXPECT_FALSE(std::filesystem::exists(dir.file("refused/display.json")));
  EXPECT_FALSE(render_cli::parseRenderArgs(
      {"--rig", rig.file, "--content", "x", "--out", "y", "--viewer", "1,2"}));
}

}  // namespace
}  // namespace procam::itest
