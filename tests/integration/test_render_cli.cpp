// procam-render on the virtual rig's tiled_wall (four 1280x800 projectors, 2x2, gammas
// 2.0-2.6, brightness +-20 %), from the scene's true rig model handed over explicitly
// (with each projector's true response and brightness across its frame as its
// photometric record):
//  - geometry: a 16-bit content ramp drawn geometry-only, every framebuffer pixel's
//    code read back as a content coordinate and compared with where the TRUE projector
//    puts that pixel on the TRUE wall, in the display rectangle display.json reports;
//  - light: the 8-bit blended frames (the daemon's) lighting the scene, white content
//    seen from the scene's viewer in linear light: no step above 2 % ([Raskar02] eq. 4.3
//    weights in linear light, §4.1.2; matched per pixel, [Majumder05]) between
//    neighbouring viewer pixels, 16-bit and 8-bit;
//  - bad input: clear errors, nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "blend/mpcdi.hpp"
#include "content_ramp.hpp"
#include "core/pfm.hpp"
#include "daemon_harness.hpp"
#include "mpcdi_readback.hpp"
#include "mpcdi_zip.hpp"
#include "render_command.hpp"
#include "rig/rig_model.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "true_brightness.hpp"

namespace procam::itest {
namespace {

constexpr int kW = 1600, kH = 1000;  // content size

struct Rig {
  sim::Scene scene;
  sim::SceneState state;
  std::string file;
};

// The true rig of tiled_wall with each projector's true response as rig.json
// photometric (black 0, white its brightness and its white across the frame: what a
// linear camera would measure).
Rig trueTiledWall(const TempDir& dir) {
  auto scene = sim::resolveScene("tiled_wall");
  EXPECT_TRUE(scene);
  Rig r{*scene, scene->at(0), ""};
  auto rig = sim::truthRig(r.scene, 0.0);
  EXPECT_TRUE(rig);
  addTruePhotometry(r.scene, r.state, *rig);
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  r.file = dir.file("rig.json");
  return r;
}

Vec3 jsonVec3(const json& a) {
  return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
}

TEST(RenderCli, FramebuffersPutEveryContentPixelWhereTheTrueProjectorsShowIt) {
  TempDir dir;
  const Rig rig = trueTiledWall(dir);
  const cv::Mat ramp = contentRamp(kW, kH);
  ASSERT_TRUE(cv::imwrite(dir.file("ramp.png"), ramp));
  auto args =
      render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("ramp.png"), "--out",
                                   dir.file("frames"), "--bit-depth", "16", "--geometry-only"});
  ASSERT_TRUE(args) << args.error().message;
  auto doc = render_cli::runRender(*args);
  ASSERT_TRUE(doc) << doc.error().message;
  ASSERT_EQ((*doc)["projectors"].size(), 4u) << doc->dump();
  const json& display = (*doc)["display"];
  const Vec3 centre = jsonVec3(display["centre_world"]);
  const Vec3 u = jsonVec3(display["basis"]["u"]), v = jsonVec3(display["basis"]["v"]);
  const double width = display["size_m"][0].get<double>(), height = display["size_m"][1];
  EXPECT_NEAR(width / height, double(kW) / kH, 1e-9);
  EXPECT_NEAR(v.z(), 1.0, 1e-9) << "the display's up is world up";
  RampError error{kW, kH};
  for (const auto& p : rig.state.projectors) {
    const cv::Mat frame =
        cv::imread(dir.file("frames/" + p.spec.name + ".png"), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(frame.type(), CV_16UC3) << p.spec.name;
    ASSERT_EQ(frame.size(), cv::Size(p.spec.width, p.spec.height));
    for (int y = 2; y < frame.rows; y += 7) {
      for (int x = 2; x < frame.cols; x += 7) {
        // The TRUE wall point of this pixel, as content pixels of the reported display.
        const geom::CameraModel& m = p.model;
        const Vec3 dir3 = m.pose.R.transpose() * m.K.matrix().inverse() * Vec3(x, y, 1);
        const Vec3 c = m.pose.center();
        const Vec3 wall = c + dir3 * ((3.0 - c.y()) / dir3.y());
        const double cx = ((wall - centre).dot(u) / width + 0.5) * kW - 0.5;
        const double cy = (0.5 - (wall - centre).dot(v) / height) * kH - 0.5;
        // Inside the content, one pixel in from its edge (the edge half pixel is clamped).
        if (cx < 1 || cy < 1 || cx > kW - 2 || cy > kH - 2) continue;
        error.add(frame.at<cv::Vec3w>(y, x), Vec2(cx, cy));
      }
    }
  }
  ASSERT_GT(error.n, 10000);
  std::printf(
      "[ figures  ] procam-render geometry: %ld framebuffer pixels, content position "
      "error RMS %.4f px, max %.4f px\n",
      error.n, error.rms(), error.worst);
  // 16-bit codes resolve 1/41 content px; the homographies come from the true rig exactly.
  EXPECT_LT(error.rms(), 0.02);
  EXPECT_LT(error.worst, 0.05);
}

struct Light {
  double step = 1, uniformity = 0;
  Vec2 at = Vec2::Zero();  // the largest step, in display half-sizes from the centre
  long pixels = 0;
};

// White content drawn at `bit_depth`, lighting the scene; the viewer's image over the
// display inset by 3 % in linear light.
Light whiteSeenByTheViewer(const TempDir& dir, const Rig& rig, const std::string& bit_depth) {
  Light out;
  const std::string frames = dir.file("frames" + bit_depth);
  auto doc = render_cli::runRender(
      *render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("white.png"), "--out",
                                    frames, "--bit-depth", bit_depth}));
  EXPECT_TRUE(doc) << doc.error().message;
  if (!doc) return out;
  EXPECT_EQ((*doc)["blend"]["response"], "measured");
  const json& matching = (*doc)["blend"]["photometric"];
  EXPECT_EQ(matching["matching"], "per-pixel") << matching.dump();
  if (bit_depth == "8")
    std::printf("[ figures  ] procam-render matching: %s\n", matching.dump().c_str());
  sim::Framebuffers shown;
  for (const auto& p : rig.state.projectors) {
    shown[p.spec.name] = cv::imread(frames + "/" + p.spec.name + ".png", cv::IMREAD_UNCHANGED);
    EXPECT_FALSE(shown[p.spec.name].empty());
  }
  auto lit = sim::Renderer::create(rig.scene, rig.state, shown);
  EXPECT_TRUE(lit);
  if (!lit) return out;
  const cv::Mat view = lit->renderViewer(4);
  const json& display = (*doc)["display"];
  const Vec3 centre = jsonVec3(display["centre_world"]);
  const Vec3 u = jsonVec3(display["basis"]["u"]), v = jsonVec3(display["basis"]["v"]);
  const double hw = 0.5 * display["size_m"][0].get<double>();
  const double hh = 0.5 * display["size_m"][1].get<double>();
  const geom::CameraModel& eye = rig.state.viewer;
  auto wallOf = [&](int x, int y) -> std::optional<Vec2> {
    auto ray = eye.backproject(Vec2(x, y));
    if (!ray || !(ray->dir.y() > 0)) return std::nullopt;
    const Vec3 p = ray->origin + ray->dir * ((3.0 - ray->origin.y()) / ray->dir.y());
    return Vec2((p - centre).dot(u) / hw, (p - centre).dot(v) / hh);
  };
  auto inside = [&](int x, int y) {
    const auto q = wallOf(x, y);
    return q && std::abs(q->x()) < 0.97 && std::abs(q->y()) < 0.97;
  };
  double lo = 1e9, hi = 0;
  out.step = 0;
  for (int y = 0; y + 1 < view.rows; ++y) {
    for (int x = 0; x + 1 < view.cols; ++x) {
      if (!inside(x, y) || !inside(x + 1, y + 1)) continue;
      const double l = view.at<cv::Vec3f>(y, x)[0];
      EXPECT_GT(l, 0) << "an unlit point inside the display at viewer pixel " << x << "," << y;
      if (!(l > 0)) return out;
      const double st = std::max(std::abs(view.at<cv::Vec3f>(y, x + 1)[0] - l) / l,
                                 std::abs(view.at<cv::Vec3f>(y + 1, x)[0] - l) / l);
      if (st > out.step) {
        out.step = st;
        out.at = *wallOf(x, y);
      }
      lo = std::min(lo, l);
      hi = std::max(hi, l);
      ++out.pixels;
    }
  }
  out.uniformity = hi > 0 ? lo / hi : 0;
  std::printf(
      "[ figures  ] procam-render light, %s-bit frames: %ld viewer pixels, largest step "
      "%.2f %% at (%.3f, %.3f) display half-sizes from the centre, uniformity min/max "
      "%.3f\n",
      bit_depth.c_str(), out.pixels, 100 * out.step, out.at.x(), out.at.y(), out.uniformity);
  return out;
}

// 16-bit frames carry the unquantized weights; 8-bit ones are the daemon's frames, whose
// weights pass an 8-bit alpha mask.
TEST(RenderCli, BlendedFramesLightTheWallEvenly) {
  TempDir dir;
  const Rig rig = trueTiledWall(dir);
  ASSERT_TRUE(cv::imwrite(dir.file("white.png"), cv::Mat(kH, kW, CV_8UC3, cv::Scalar::all(255))));
  const Light precise = whiteSeenByTheViewer(dir, rig, "16");
  EXPECT_GT(precise.pixels, 1000);
  EXPECT_LE(precise.step, 0.02);
  const Light daemon = whiteSeenByTheViewer(dir, rig, "8");
  EXPECT_GT(daemon.pixels, 1000);
  EXPECT_LE(daemon.step, 0.02);
}

// The MPCDI export read back (zip, mpcdi.xml, warps, alpha maps) and drawn as a 2D-profile
// player draws it gives procam-render's own 16-bit framebuffers within 0.5 of an 8-bit
// code value.
TEST(RenderCli, MpcdiPackageRebuildsTheSameFramebuffers) {
  TempDir dir;
  const Rig rig = trueTiledWall(dir);
  cv::Mat content(500, 800, CV_8UC3);
  for (int y = 0; y < content.rows; ++y) {
    for (int x = 0; x < content.cols; ++x) {
      content.at<cv::Vec3b>(y, x) = {uint8_t(x * 255 / 799), uint8_t(y * 255 / 499),
                                     uint8_t(128 + 100 * std::sin(x * 0.05) * std::cos(y * 0.07))};
    }
  }
  ASSERT_TRUE(cv::imwrite(dir.file("slide.png"), content));
  const std::string package = dir.file("wall.mpcdi");
  auto doc = render_cli::runRender(
      *render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("slide.png"), "--out",
                                    dir.file("frames"), "--bit-depth", "16", "--mpcdi", package}));
  ASSERT_TRUE(doc) << doc.error().message;
  const double worst = mpcdiDifference(package, dir.file("frames"), content, 4);
  std::printf(
      "[ figures  ] MPCDI read back: 4 regions, largest difference from procam-render's "
      "frames %.4f 8-bit code values\n",
      worst);
  EXPECT_GE(worst, 0);
  EXPECT_LE(worst, 0.5);
  auto files = render_cli::readMpcdiZip(package);
  ASSERT_TRUE(files) << files.error().message;
  // Damaged packages are refused with a reason.
  dir.write("broken.mpcdi", "PK not really a zip");
  EXPECT_FALSE(render_cli::readMpcdiZip(dir.file("broken.mpcdi")));
  auto without_xml = *files;
  without_xml.erase(without_xml.begin());
  EXPECT_EQ(blend::readMpcdi2d(without_xml).error().code, ErrorCode::kParse);
  auto without_warp = *files;
  without_warp.erase(without_warp.begin() + 1);
  EXPECT_EQ(blend::readMpcdi2d(without_warp).error().code, ErrorCode::kParse);
  // A PFM that ends at its header, or holds a NaN, is refused.
  EXPECT_FALSE(decodePfm("Pf\n1 1\n-1"));
  std::string nan_pfm = "Pf\n1 1\n-1\n";
  const float nan = std::nanf("");
  nan_pfm.append(reinterpret_cast<const char*>(&nan), 4);
  EXPECT_FALSE(decodePfm(nan_pfm));
}

TEST(RenderCli, BadInputIsRefusedWithAReason) {
  TempDir dir;
  const Rig rig = trueTiledWall(dir);
  ASSERT_TRUE(cv::imwrite(dir.file("c.png"), cv::Mat(100, 160, CV_8UC3, cv::Scalar::all(128))));
  const std::string out = dir.file("out");
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = {"--rig", rig.file, "--content", dir.file("c.png"), "--out", out};
    a.insert(a.end(), extra.begin(), extra.end());
    auto parsed = render_cli::parseRenderArgs(a);
    if (!parsed) return parsed.error();
    auto done = render_cli::runRender(*parsed);
    // A run that succeeds is no error of any kind.
    return done ? Error{ErrorCode::kInternal, "ran without an error"} : done.error();
  };
  EXPECT_EQ(run({"--bit-depth", "12"}).code, ErrorCode::kInvalidInput);
  EXPECT_EQ(run({"--rect", "1,2,3"}).code, ErrorCode::kInvalidInput);
  EXPECT_EQ(run({"--rect", "0,3,1.5,-1,1"}).code, ErrorCode::kInvalidInput);
  EXPECT_EQ(run({"--projector", "nobody"}).code, ErrorCode::kNotFound);
  EXPECT_EQ(run({}).message, "ran without an error");
  std::filesystem::remove_all(out);
  // A projector name is a file name: one that would leave --out is refused before
  // anything is written.
  {
    std::ifstream in(rig.file);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string from = "\"name\": \"proj_tl\"";
    ASSERT_NE(text.find(from), std::string::npos);
    text.replace(text.find(from), from.size(), "\"name\": \"../escaped\"");
    dir.write("hostile.json", text);
    auto parsed = render_cli::parseRenderArgs({"--rig", dir.file("hostile.json"), "--content",
                                               dir.file("c.png"), "--out", dir.file("h/out")});
    ASSERT_TRUE(parsed);
    auto done = render_cli::runRender(*parsed);
    ASSERT_FALSE(done);
    EXPECT_EQ(done.error().code, ErrorCode::kInvalidInput) << done.error().message;
    EXPECT_FALSE(std::filesystem::exists(dir.file("h"))) << "nothing written";
    EXPECT_FALSE(std::filesystem::exists(dir.file("escaped.png")));
  }
  const Error off_wall = run({"--rect", "0,2.5,1.5,1,0.6"});  // 0.5 m in front of the wall
  EXPECT_EQ(off_wall.code, ErrorCode::kInvalidInput);
  EXPECT_NE(off_wall.message.find("off the wall plane"), std::string::npos) << off_wall.message;
  const Error outside = run({"--rect", "0,3,1.5,40,25"});  // wider than every image
  EXPECT_NE(outside.message.find("outside the projectors' images"), std::string::npos)
      << outside.message;
  dir.write("broken.json", "{\"version\": 2, \"projectors\": [");
  auto parsed = render_cli::parseRenderArgs(
      {"--rig", dir.file("broken.json"), "--content", dir.file("c.png"), "--out", out});
  ASSERT_TRUE(parsed);
  EXPECT_FALSE(render_cli::runRender(*parsed));
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing written for a failed run";
  // The binary: exit 2 for a bad command line, 1 for a failure, each with a message.
  const std::string bin = PROCAM_RENDER_BIN;
  EXPECT_EQ(WEXITSTATUS(std::system((bin + " --out x >/dev/null 2>&1").c_str())), 2);
  EXPECT_EQ(
      WEXITSTATUS(std::system((bin + " --rig " + dir.file("broken.json") + " --content " +
                               dir.file("c.png") + " --out " + out + " 2>" + dir.file("err.txt"))
                                  .c_str())),
      1);
  std::ifstream err(dir.file("err.txt"));
  const std::string message((std::istreambuf_iterator<char>(err)),
                            std::istreambuf_iterator<char>());
  EXPECT_NE(message.find("procam-render:"), std::string::npos) << message;
  // A given rectangle on the wall inside the union: used, shrunk to the content's aspect.
  auto given = render_cli::runRender(
      *render_cli::parseRenderArgs({"--rig", rig.file, "--content", dir.file("c.png"), "--out", out,
                                    "--rect", "0,3,1.5,1.6,0.8"}));
  ASSERT_TRUE(given) << given.error().message;
  EXPECT_EQ((*given)["display"]["rect_source"], "given");
  EXPECT_NEAR((*given)["display"]["size_m"][0].get<double>(), 1.28, 1e-9);
  EXPECT_NEAR((*given)["display"]["size_m"][1].get<double>(), 0.8, 1e-9);
}

}  // namespace
}  // namespace procam::itest
