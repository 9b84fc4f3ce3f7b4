// Three projectors on a curved wall shown as one display for a viewer at the sweet
// spot, end to end on the virtual rig over the socket only: cylinder3 (three 1280x800
// projectors with unmatched responses, here with lenses, inside a cylinder, two
// cameras) with nothing
// handed over but the cameras' calibration (TruthParts::kCamerasOnly) and the viewer's
// position in procamd.toml. calibrate (route a) triangulates each projector's pose and
// its piece of the wall, content load makes one display of them ([Raskar02] §4.1.5)
// feathered in the overlaps (eq. 4.3) and drawn through each projector's
// post-rendering warp (§4.1.3), and the daemon's lookup warps and weights,
// rebuilt from the rig.json it wrote and the viewer matrix it reports, are judged with
// the TRUE projectors and wall.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "blend/curved_display.hpp"
#include "blend/rig_tiles.hpp"
#include "content/mesh_content.hpp"
#include "curved_display_checks.hpp"
#include "cylinder_scene.hpp"
#include "daemon_harness.hpp"
#include "json_matrix.hpp"
#include "render/viewer_view.hpp"
#include "rig/rig_model.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

const char* const kOutputs[] = {"proj_l", "proj_c", "proj_r"};
constexpr int kW = 4800, kH = 900;  // a panorama

TEST(SimCurvedWall, ThreeProjectorsCalibratedIntoOneDisplayForTheSweetSpot) {
  TempDir dir;
  dir.write("cylinder3_lenses.toml", withProjectorLenses(cylinder3Text()));
  const std::string scene_file = dir.file("cylinder3_lenses.toml");
  auto scene = sim::resolveScene(scene_file);
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  std::map<std::string, geom::CameraModel> truth;
  std::map<std::string, sim::ProjectorSpec> spec;
  for (const auto& p : state.projectors) {
    truth[p.spec.name] = p.model;
    spec[p.spec.name] = p.spec;
  }
  const Vec3 eye = state.viewer.pose.center();
  dir.write("procamd.toml", "[sim]\nscene = \"" + scene_file + "\"\n[content]\nviewer = [" +
                                std::to_string(eye.x()) + ", " + std::to_string(eye.y()) + ", " +
                                std::to_string(eye.z()) + "]\n");
  DaemonProcess d(dir,
                  DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--rig",
                                         truthRigFile(dir, scene_file, TruthParts::kCamerasOnly)},
                                        {},
                                        -1,
                                        true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Every projector in turn through both cameras (route a); one rig model at the end.
  const auto t0 = std::chrono::steady_clock::now();
  const json request = {{"cmd", "calibrate"},
                        {"id", 1},
                        {"projectors", "all"},
                        {"cameras", {"cam_a", "cam_b"}},
                        {"mode", "gray+phase"},
                        {"phase_steps", 3},
                        {"grid", 8},
                        {"settle_frames", 0}};
  auto started = c.call(request);
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  auto done = finalReply(c, 1, kSlowdown * 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  ASSERT_EQ((*done)["outputs"].size(), 3u) << done->dump();
  for (const json& o : (*done)["outputs"]) {
    const std::string name = o["output"].get<std::string>();
    checkRouteAOutput(o, truth[name], spec[name].gamma);
  }
  // The three meshes unified where they overlap ([Raskar02] eq. 4.4): before, two
  // triangulations of the same wall differ by their noise; after, by far less.
  const json& unified = (*done)["unified"];
  ASSERT_TRUE(unified.is_object()) << done->dump();
  std::printf(
      "[ figures  ] meshes unified: %d of %d vertices shared, %.3f mm apart RMS (max "
      "%.3f) before, %.3f mm (max %.3f) after\n",
      unified["shared"].get<int>(), unified["vertices"].get<int>(),
      unified["gap_rms_mm"].get<double>(), unified["gap_max_mm"].get<double>(),
      unified["gap_after_rms_mm"].get<double>(), unified["gap_after_max_mm"].get<double>());
  EXPECT_EQ(unified["meshes"], 3);
  EXPECT_GT(unified["shared"].get<int>(), 100);
  EXPECT_LT(unified["gap_after_rms_mm"].get<double>(), 0.5 * unified["gap_rms_mm"].get<double>());
  // proj_l and proj_r light disjoint parts of the wall: scanned together, then proj_c.
  EXPECT_EQ((*done)["scan"]["batches"], json({{"proj_l", "proj_r"}, {"proj_c"}})) << done->dump();
  std::printf(
      "[ figures  ] three projectors calibrated in %.1f s: %d captures in %zu scan batches "
      "(%d announced: one at a time, and the coarse pass)\n",
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
      (*done)["scan"]["captures"].get<int>(), (*done)["scan"]["batches"].size(),
      (*started)["captures"].get<int>());
  EXPECT_LT((*done)["scan"]["captures"].get<int>(), (*started)["captures"].get<int>());

  // A white panorama on the one display.
  const std::string png = contentFile(dir, "panorama.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255))));
  LookupDisplay drawn = loadOntoLookupDisplay(c, png, 3);
  ASSERT_TRUE(drawn.ready) << drawn.display.dump() << "\n" << d.log();
  const json& display = drawn.display;
  std::map<std::string, json>& shown = drawn.shown;
  EXPECT_EQ(display["outputs"], json({"proj_l", "proj_c", "proj_r"})) << display.dump();
  EXPECT_EQ(display["viewer"]["source"], "config");
  EXPECT_EQ(display["blend"]["response"], "measured");
  // Matched per pixel from the brightness maps calibrate measured ([Majumder05]).
  const json& matching = display["blend"]["photometric"];
  EXPECT_EQ(matching["matching"], "per-pixel") << display.dump();
  std::printf("[ figures  ] matching: %s\n", matching.dump().c_str());
  const Mat34 V = rowMajor34(display["viewer_matrix"]);
  for (const char* name : kOutputs) {
    EXPECT_EQ(rowMajor34(shown[name]["viewer_matrix"]), V) << name;
    EXPECT_EQ(shown[name]["display"]["surface"], "mesh");
  }

  // The same display from the rig model the daemon wrote: what every output draws.
  Calibrated cal;
  ASSERT_NO_FATAL_FAILURE(readCalibrated(dir.file("state"), {kOutputs, kOutputs + 3}, cal));
  auto blend = blend::makeCurvedBlend(cal.projectors, cal.responses, eye, {kW, kH});
  ASSERT_TRUE(blend) << blend.error().message;
  EXPECT_LT((blend->display.viewer - V).norm(), 1e-9 * V.norm());
  const auto& lookup = blend->display.lookup;

  TrueRig true_rig{&*scene, {}};
  for (const char* name : kOutputs) true_rig.projectors.push_back(truth[name]);

  // Seams: where one projector puts a content point on the TRUE wall, the other shows
  // the same content point within 0.3 px RMS, 1 px at most (its pixels).
  const SeamFigures seams = seamsOnTheTrueSurface(lookup, true_rig, {kW, kH});
  ASSERT_GT(seams.pairs, 1000);
  std::printf("[ figures  ] seams: %d content points lit twice, RMS %.3f px, max %.3f px\n",
              seams.pairs, seams.rms, seams.worst);
  EXPECT_LE(seams.rms, 0.3);
  EXPECT_LE(seams.worst, 1.0);
  // Each projector's post-rendering warp ([Raskar02] §4.1.3), measured from its mesh's
  // pixels: the lens the pinhole left out. Without it the seams open by the lenses'
  // difference.
  for (std::size_t t = 0; t < 3; ++t) {
    ASSERT_TRUE(cal.warps[t]) << kOutputs[t];
    EXPECT_EQ(cal.warps[t]->source, render::PostRenderWarp::Source::kMeasured);
    const json& reported = display["tiles"][t]["post_warp"];
    std::printf(
        "[ figures  ] %s: post-rendering warp from %d vertices, moves the pinhole's "
        "pixels %.3f px RMS, %.3f px at most (daemon: %s)\n",
        kOutputs[t], cal.warps[t]->points, cal.warps[t]->rms_px, cal.warps[t]->max_px,
        reported.dump().c_str());
    EXPECT_EQ(reported["source"], "measured") << kOutputs[t];
    EXPECT_NEAR(reported["rms_px"].get<double>(), cal.warps[t]->rms_px, 1e-9) << kOutputs[t];
  }
  std::vector<blend::SurfaceProjector> pinholes = cal.projectors;
  for (auto& p : pinholes) p.post_warp.reset();
  auto pinhole_only = blend::makeCurvedBlend(pinholes, cal.responses, eye, {kW, kH});
  ASSERT_TRUE(pinhole_only) << pinhole_only.error().message;
  const SeamFigures open = seamsOnTheTrueSurface(pinhole_only->display.lookup, true_rig, {kW, kH});
  std::printf("[ figures  ] the pinholes alone, no warp: seams RMS %.3f px, max %.3f px\n",
              open.rms, open.worst);
  EXPECT_LT(seams.rms, open.rms);

  // Straight lines of the content stay straight for the viewer: within 0.5 content px.
  const double bent = bentOnTheTrueSurface(lookup, true_rig, V, {kW, kH});
  std::printf(
      "[ figures  ] content lines seen from the sweet spot: %.3f content px from straight\n", bent);
  EXPECT_LE(bent, 0.5);

  // The frames: white through each output's lookup warp and blend, as the daemon drew them
  // (its statistics agree), lit by the TRUE projectors and seen by the viewer in linear
  // light: no step above 2 % between neighbouring viewer pixels over the display (inset by
  // 3 %).
  sim::Framebuffers frames;
  for (std::size_t t = 0; t < 3; ++t) {
    frames[kOutputs[t]] = whiteThroughLookup(lookup[t], *blend, t, {1280, 800}, {kW, kH},
                                             shown[kOutputs[t]], kOutputs[t]);
  }
  auto lit = sim::Renderer::create(*scene, state, frames);
  ASSERT_TRUE(lit) << lit.error().message;
  const cv::Mat view = lit->renderViewer(4);
  const geom::CameraModel& viewer = state.viewer;
  auto inside = [&](int x, int y) {
    auto ray = viewer.backproject(Vec2(x, y));
    if (!ray) return false;
    auto hit = scene->world().intersect(*ray);
    if (!hit) return false;
    const Vec2 q = (V * hit->hit.point.homogeneous()).hnormalized();
    return q.x() > 0.03 * kW && q.x() < 0.97 * kW && q.y() > 0.03 * kH && q.y() < 0.97 * kH;
  };
  const ViewerLight light = viewerLight(view, inside);
  EXPECT_FALSE(light.unlit) << "an unlit point inside the display at viewer pixel "
                            << light.unlit->transpose();
  std::printf(
      "[ figures  ] white seen from the sweet spot: largest step %.2f %% at viewer pixel (%.0f, "
      "%.0f), uniformity min/max %.3f\n",
      100 * light.step, light.at.x(), light.at.y(), light.uniformity());
  EXPECT_GT(light.pixels, 10000);
  EXPECT_LE(light.step, 0.02);
}

}  // namespace
}  // namespace procam::itest
