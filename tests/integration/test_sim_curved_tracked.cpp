// One display across projectors on a curved wall for a viewer a head tracker follows:
// cylinder3 (its projectors with lenses) with its sweet-spot viewer walking 0.6 m side
// to side and a tracker on the head, the TRUE rig handed over explicitly (poses, lenses,
// the wall as a mesh, each projector's true response and brightness: this checks
// drawing, not calibration, which SimCurvedWall checks). The display is made for the
// sweet spot ([content] viewer) and every output draws it for the tracked eye through
// the two-pass path ([Raskar02] §3.2.3, §4.1.2) and its lens's post-rendering warp
// (§4.1.3). Judged with the TRUE projectors and wall for the eye the outputs drew
// for: all outputs share one display (seams), content lines stay straight, the daemon's
// frame statistics match the frames rebuilt from the rig, and white seen by the viewer
// standing there has no step above 2 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "blend/brightness_map.hpp"
#include "curved_display_checks.hpp"
#include "cylinder_mesh.hpp"
#include "cylinder_scene.hpp"
#include "daemon_harness.hpp"
#include "json_matrix.hpp"
#include "render/cpu_renderer.hpp"
#include "sim/renderer.hpp"
#include "sim/truth_rig.hpp"
#include "true_brightness.hpp"

namespace procam::itest {
namespace {

const std::vector<std::string> kCylinderOutputs = {"proj_l", "proj_c", "proj_r"};
constexpr int kPanoramaW = 2400, kPanoramaH = 450;  // a panorama
const Vec3 kSweetSpot(0.0, -0.6, 1.6);

// cylinder3 with lenses, its viewer walking x = -0.3 ... 0.3 m in 4 s and back, and a head
// tracker (1 mm noise, 60 Hz) reporting it.
std::string walkingCylinder() {
  const std::string text = withProjectorLenses(cylinder3Text());
  const auto viewer = text.find("[viewer]");
  EXPECT_NE(viewer, std::string::npos);
  if (viewer == std::string::npos) return "";
  return text.substr(0, viewer) + R"([[trajectories]]
name = "walk"
loop = true
keyframes = [
  { t = 0.0, position = [-0.3, -0.6, 1.6], look_at = [0.0, 3.0, 1.6] },
  { t = 4.0, position = [0.3, -0.6, 1.6], look_at = [0.0, 3.0, 1.6] },
  { t = 8.0, position = [-0.3, -0.6, 1.6], look_at = [0.0, 3.0, 1.6] },
]

[viewer]
trajectory = "walk"
resolution = [960, 400]
intrinsics = { hfov_deg = 140.0 }

[[trackers]]
name = "head"
noise_sigma_m = 0.001
rate_hz = 60.0
)";
}

// The eye of a world -> content pixel pinhole: its null vector.
Vec3 eyeOf(const Mat34& V) {
  return -V.leftCols<3>().inverse() * V.col(3);
}

TEST(SimCurvedTracked, EveryOutputDrawsTheSweetSpotDisplayForTheTrackedEye) {
  TempDir dir;
  dir.write("walk.toml", walkingCylinder());
  auto scene = sim::Scene::parse(walkingCylinder(), dir.file("walk.toml"), {});
  ASSERT_TRUE(scene) << scene.error().message;
  auto rig = sim::truthRig(*scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  const sim::SceneState at0 = scene->at(0);
  for (auto& p : rig->projectors) {
    for (std::size_t i = 0; i < at0.projectors.size(); ++i) {
      const auto& s = at0.projectors[i].spec;
      if (s.name != p.name) continue;
      p.photometric = {{"response_gamma", s.gamma},
                       {"black", 0.0},
                       {"white", s.brightness},
                       {"brightness", blend::brightnessToJson(trueBrightness(*scene, at0, i))},
                       {"camera", "truth"}};
    }
  }
  rig->surface = {};
  rig->surface.unified_mesh = "wall.ply";
  rig->viewer = {};
  dir.write("rig.json", rig::rigToJson(*rig).dump(2) + "\n");
  std::filesystem::create_directories(dir.file("state"));
  dir.write("state/wall.ply", cylinderPly());
  dir.write("procamd.toml", "[sim]\nscene = \"" + dir.file("walk.toml") +
                                "\"\n[content]\nviewer = [0.0, -0.6, 1.6]\n");
  DaemonProcess d(
      dir,
      DaemonProcess::Launch{
          {"--config", dir.file("procamd.toml"), "--rig", dir.file("rig.json")}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  const std::string png = contentFile(dir, "white.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(kPanoramaH, kPanoramaW, CV_8UC3, cv::Scalar::all(255))));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, kSlowdown * 30s);
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  json status;
  std::map<std::string, json> shown;
  const bool ready = eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        if (!s) return false;
        status = *s;
        shown.clear();
        for (const json& o : status["outputs"]["shown"]) {
          if (o["source"] == "content" && o.value("path", "") == "two-pass-mesh" &&
              o.contains("display") && o.contains("viewer_matrix")) {
            shown[o["name"].get<std::string>()] = o;
          }
        }
        return shown.size() == 3;
      },
      kSlowdown * 60s);
  ASSERT_TRUE(ready) << status.dump() << "\n" << d.log();
  EXPECT_EQ(status["viewer"]["source"], "tracker") << status["viewer"].dump();
  const json& display = status["outputs"]["display"];
  ASSERT_EQ(display["state"], "ready") << display.dump();
  EXPECT_EQ(display["viewer"]["source"], "config");
  EXPECT_EQ(display["blend"]["photometric"]["matching"], "per-pixel") << display.dump();

  // The display for the sweet spot, rebuilt from the same rig.
  auto mesh = content::loadMeshContent(dir.file("state/wall.ply"));
  ASSERT_TRUE(mesh) << mesh.error().message;
  render::SurfaceMesh drawn;
  drawn.vertices = mesh->mesh.vertices;
  for (const auto& f : mesh->mesh.faces) drawn.triangles.push_back({f.x(), f.y(), f.z()});
  auto wall = geom::MeshIntersector::build(std::move(mesh->mesh));
  ASSERT_TRUE(wall);
  std::vector<blend::SurfaceProjector> projectors;
  std::vector<std::optional<blend::ProjectorResponse>> responses;
  for (std::size_t t = 0; t < 3; ++t) {
    const rig::RigProjector* p = rig->projectorForOutput(kCylinderOutputs[t]);
    // The rig's lenses: each output draws the pinhole through its lens's warp.
    auto warp = render::projectorPostRenderWarp(p->model(), nullptr);  // one shared wall
    ASSERT_TRUE(warp && *warp) << kCylinderOutputs[t];
    EXPECT_EQ((*warp)->source, render::PostRenderWarp::Source::kLens);
    EXPECT_EQ(display["tiles"][t]["post_warp"], blend::postWarpJson(**warp)) << display.dump();
    projectors.push_back({&*wall, p->model().projectionMatrix(), cv::Size(p->width, p->height),
                          std::shared_ptr<const render::WarpGrid>(*warp, &(*warp)->grid)});
    responses.push_back(blend::projectorResponse(*p));
  }
  auto blend = blend::makeCurvedBlend(projectors, responses, kSweetSpot, {kPanoramaW, kPanoramaH});
  ASSERT_TRUE(blend) << blend.error().message;

  // Each output drew that display for a tracked eye on the walk.
  std::map<std::string, Mat34> V;
  for (const std::string& name : kCylinderOutputs) {
    V[name] = rowMajor34(shown[name]["viewer_matrix"]);
    const Vec3 eye = eyeOf(V[name]);
    std::printf("[ figures  ] %s drew for the eye at (%.3f, %.3f, %.3f)\n", name.c_str(), eye.x(),
                eye.y(), eye.z());
    EXPECT_NEAR(eye.y(), -0.6, 0.01) << name;  // the tracker's noise is 1 mm
    EXPECT_NEAR(eye.z(), 1.6, 0.01) << name;
    EXPECT_LE(std::abs(eye.x()), 0.31) << name;
    const Mat34 expected = render::contentViewMatrix(blend->display.rotation, eye,
                                                     blend->display.rect, {kPanoramaW, kPanoramaH});
    EXPECT_LT((V[name] - expected).norm(), 1e-6 * expected.norm()) << name;
  }

  // Geometry for one eye (the first output's), every output's two-pass drawing rebuilt as
  // lookups: the outputs agree where they overlap, and lines stay straight.
  const Mat34& V0 = V[kCylinderOutputs[0]];
  std::vector<render::WarpGrid> lookup;
  for (std::size_t m = 0; m < 3; ++m) {
    auto g = render::lookupGridForViewer(*wall, projectors[m].projector, projectors[m].size, V0, 8,
                                         projectors[m].post_warp);
    ASSERT_TRUE(g) << g.error().message;
    lookup.push_back(std::move(*g));
  }
  TrueRig true_rig{&*scene, {}};
  for (const std::string& name : kCylinderOutputs) {
    for (const auto& p : at0.projectors) {
      if (p.spec.name == name) true_rig.projectors.push_back(p.model);
    }
  }
  const SeamFigures seams = seamsOnTheTrueSurface(lookup, true_rig, {kPanoramaW, kPanoramaH});
  ASSERT_GT(seams.pairs, 1000);
  std::printf(
      "[ figures  ] seams for the tracked eye: %d content points lit twice, RMS %.3f px, "
      "max %.3f px\n",
      seams.pairs, seams.rms, seams.worst);
  EXPECT_LE(seams.rms, 0.3);
  EXPECT_LE(seams.worst, 1.0);
  // The same pinholes drawn without their lenses' warps: the seams open by the lenses.
  std::vector<render::WarpGrid> pinhole;
  for (std::size_t m = 0; m < 3; ++m) {
    auto g = render::lookupGridForViewer(*wall, projectors[m].projector, projectors[m].size, V0);
    ASSERT_TRUE(g) << g.error().message;
    pinhole.push_back(std::move(*g));
  }
  const SeamFigures open = seamsOnTheTrueSurface(pinhole, true_rig, {kPanoramaW, kPanoramaH});
  std::printf("[ figures  ] without the lenses' warps: seams RMS %.3f px, max %.3f px\n", open.rms,
              open.worst);
  EXPECT_GT(open.worst, 1.0);
  const double bent = bentOnTheTrueSurface(lookup, true_rig, V0, {kPanoramaW, kPanoramaH});
  std::printf(
      "[ figures  ] content lines seen from the tracked eye: %.3f content px from "
      "straight\n",
      bent);
  EXPECT_LE(bent, 0.5);

  // The frames: white through each output's two-pass path and blend for the eye it drew
  // for, rebuilt from the rig: the daemon's statistics agree.
  const cv::Mat white(kPanoramaH, kPanoramaW, CV_8UC4, cv::Scalar::all(255));
  auto frameFor = [&](std::size_t t, const Mat34& viewer) -> cv::Mat {
    render::RenderSetup setup;
    setup.output_size = projectors[t].size;
    setup.content_size = cv::Size(kPanoramaW, kPanoramaH);
    setup.path = render::RenderPath::kTwoPassMesh;
    setup.surface = drawn;
    setup.projector = projectors[t].projector;
    setup.viewer = viewer;
    setup.post_warp = *projectors[t].post_warp;
    setup.final_stage.alpha = blend->alpha[t];
    setup.final_stage.weight_lut = blend->weight_lut[t];
    render::CpuRenderer cpu;
    EXPECT_TRUE(cpu.configure(setup));
    EXPECT_TRUE(cpu.render({&white, nullptr, 1}));
    cv::Mat bgr;
    cv::cvtColor(cpu.frame(), bgr, cv::COLOR_RGBA2BGR);
    return bgr;
  };
  for (std::size_t t = 0; t < 3; ++t) {
    const cv::Mat bgr = frameFor(t, V[kCylinderOutputs[t]]);
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    const double lit = cv::countNonZero(grey) / double(grey.total());
    const double mean = cv::mean(bgr)[0];
    const json& o = shown[kCylinderOutputs[t]];
    std::printf("[ figures  ] %s: lit %.5f (daemon %.5f), mean %.3f (daemon %.3f)\n",
                kCylinderOutputs[t].c_str(), lit, o["lit_fraction"].get<double>(), mean,
                o["mean_rgb"][0].get<double>());
    EXPECT_NEAR(lit, o["lit_fraction"].get<double>(), 1e-3) << kCylinderOutputs[t];
    EXPECT_NEAR(mean, o["mean_rgb"][0].get<double>(), 0.1) << kCylinderOutputs[t];
  }

  // White for one eye, lit by the TRUE projectors and seen by the viewer standing there
  // (the walk's state when it passed that eye), in linear light: no step above 2 %
  // between neighbouring viewer pixels over the display (inset by 3 %). The content
  // keeps its directions from the eye, so away from the sweet spot part of it leaves
  // the images the display was made in (reported): judged where the content lies inside
  // the display for both eyes.
  const Vec3 eye0 = eyeOf(V0);
  double when = 0, nearest = 1e9;
  for (double t = 0; t < 8; t += 0.002) {
    const double gap = (scene->at(t).viewer.pose.center() - eye0).norm();
    if (gap < nearest) {
      nearest = gap;
      when = t;
    }
  }
  ASSERT_LT(nearest, 0.005) << "the eye drawn for is not on the walk";
  const sim::SceneState state = scene->at(when);
  sim::Framebuffers frames;
  for (std::size_t t = 0; t < 3; ++t) frames[kCylinderOutputs[t]] = frameFor(t, V0);
  auto lit = sim::Renderer::create(*scene, state, frames);
  ASSERT_TRUE(lit) << lit.error().message;
  const cv::Mat view = lit->renderViewer(4);
  auto inContent = [&](const Mat34& viewer, const Vec3& X) {
    const Vec2 q = (viewer * X.homogeneous()).hnormalized();
    return q.x() > 0.03 * kPanoramaW && q.x() < 0.97 * kPanoramaW && q.y() > 0.03 * kPanoramaH &&
           q.y() < 0.97 * kPanoramaH;
  };
  std::vector<std::optional<Vec3>> seen(static_cast<std::size_t>(view.rows) * view.cols);
  long in_display = 0, in_both = 0;
  for (int y = 0; y < view.rows; ++y) {
    for (int x = 0; x < view.cols; ++x) {
      auto ray = state.viewer.backproject(Vec2(x, y));
      auto hit = ray ? scene->world().intersect(*ray) : std::nullopt;
      if (!hit || !inContent(V0, hit->hit.point)) continue;
      ++in_display;
      if (!inContent(blend->display.viewer, hit->hit.point)) continue;
      ++in_both;
      seen[static_cast<std::size_t>(y) * view.cols + x] = hit->hit.point;
    }
  }
  auto inside = [&](int x, int y) {
    return seen[static_cast<std::size_t>(y) * view.cols + x].has_value();
  };
  const ViewerLight light = viewerLight(view, inside);
  EXPECT_FALSE(light.unlit) << "an unlit point inside the display at viewer pixel "
                            << light.unlit->transpose();
  std::printf(
      "[ figures  ] white seen by the viewer at x = %.3f m (t = %.3f s): %.1f %% of the "
      "content in the sweet spot's display, %ld pixels judged, largest step %.2f %%, "
      "uniformity min/max %.3f\n",
      eye0.x(), when, in_display ? 100.0 * in_both / in_display : 0.0, light.pixels,
      100 * light.step, light.uniformity());
  EXPECT_GT(light.pixels, 10000);
  EXPECT_LE(light.step, 0.02);
}

}  // namespace
}  // namespace procam::itest
