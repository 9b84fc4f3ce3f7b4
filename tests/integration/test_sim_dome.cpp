// Three projectors on a half dome shown as one dome master, end to end on the virtual
// rig over the socket only: dome3 (three 1280x800 projectors crossing the dome, two
// wide cameras near its centre) with nothing handed over but the cameras' calibration
// (TruthParts::kCamerasOnly) and, in procamd.toml, the dome master's eye (the dome's
// centre) and `projection = "dome"`. calibrate (route a) triangulates each projector's
// pose and its piece of the dome; content load of a dome master (render/dome_master.hpp)
// draws it through each projector's lookup warp ([Raskar02] §4.1.5), feathered in the
// overlaps (eq. 4.3). The display rebuilt from the rig.json the daemon wrote is judged
// with the TRUE projectors and dome: seams, where the content lands against the dome
// master's own directions, and white seen from the eye.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "blend/curved_display.hpp"
#include "curved_display_checks.hpp"
#include "daemon_harness.hpp"
#include "render/dome_master.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

const std::vector<std::string> kDomeOutputs = {"proj_a", "proj_b", "proj_c"};
constexpr int kSide = 1024;      // the dome master: 1024 x 1024
const Vec3 kEye(0.0, 0.0, 0.0);  // the dome's centre

// Where the content lands, as the dome master means it: at every lookup node inside
// the content, the content pixel of the direction from the eye to the TRUE dome point
// the TRUE projector's pixel lights, against the content pixel the lookup shows there.
struct Placement {
  double rms = 0, worst = 0;
  int nodes = 0;
};
Placement placedOnTheTrueDome(const std::vector<render::WarpGrid>& lookup, const TrueRig& truth,
                              const render::DomeMaster& master) {
  Placement out;
  double sq = 0;
  for (std::size_t m = 0; m < lookup.size(); ++m) {
    const auto& g = lookup[m];
    for (int j = 0; j < g.rows; ++j) {
      for (int i = 0; i < g.cols; ++i) {
        const Vec2 c = g.at(i, j);
        if (c.x() == render::kOutside || !truth.inFrame(m, g.node(i, j), 1)) continue;
        const auto X = truth.lit(m, g.node(i, j));
        if (!X) continue;
        const auto meant = master.contentPixel(*X);
        if (!meant) continue;
        const double e = (*meant - c).norm();
        sq += e * e;
        out.worst = std::max(out.worst, e);
        ++out.nodes;
      }
    }
  }
  out.rms = out.nodes ? std::sqrt(sq / out.nodes) : 0;
  return out;
}

TEST(SimDome, ThreeProjectorsCalibratedIntoOneDomeMaster) {
  auto scene = sim::resolveScene("dome3");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  ASSERT_EQ(state.cameras.size(), 2u);
  std::map<std::string, geom::CameraModel> truth;
  std::map<std::string, sim::ProjectorSpec> spec;
  for (const auto& p : state.projectors) {
    truth[p.spec.name] = p.model;
    spec[p.spec.name] = p.spec;
  }
  TempDir dir;
  dir.write("procamd.toml",
            "[sim]\nscene = \"dome3\"\n[content]\nviewer = [0.0, 0.0, 0.0]\n"
            "projection = \"dome\"\ndome_front = [0.0, 1.0, 0.0]\ndome_fov_deg = 180.0\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--config", dir.file("procamd.toml"), "--rig",
                                              truthRigFile(dir, "dome3", TruthParts::kCamerasOnly)},
                                             {},
                                             -1,
                                             true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Every projector through both cameras (route a); one rig model at the end.
  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call({{"cmd", "calibrate"},
                         {"id", 1},
                         {"projectors", "all"},
                         {"cameras", {"cam", "cam_b"}},
                         {"mode", "gray+phase"},
                         {"phase_steps", 3},
                         {"grid", 8},
                         {"settle_frames", 0}});
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
  std::printf("[ figures  ] three projectors calibrated in %.1f s: %d captures in %zu batches\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
              (*done)["scan"]["captures"].get<int>(), (*done)["scan"]["batches"].size());

  // A white dome master on the three outputs.
  const std::string png = contentFile(dir, "master.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(kSide, kSide, CV_8UC3, cv::Scalar::all(255))));
  LookupDisplay loaded = loadOntoLookupDisplay(c, png, 3);
  ASSERT_TRUE(loaded.ready) << loaded.display.dump() << "\n" << d.log();
  const json& display = loaded.display;
  std::map<std::string, json>& shown = loaded.shown;
  EXPECT_EQ(display["projection"], "dome") << display.dump();
  EXPECT_EQ(display["outputs"], json(kDomeOutputs)) << display.dump();
  EXPECT_EQ(display["dome"]["fov_deg"], 180.0);
  EXPECT_EQ(display["blend"]["response"], "measured");
  // The master is made for the static eye, whatever ir_head reports; its content is
  // directions, so no world -> content matrix is reported.
  for (const auto& [name, o] : shown) {
    EXPECT_EQ(o.value("chosen_path", ""), "lookup-warp") << o.dump();
    EXPECT_FALSE(o.contains("viewer_matrix")) << o.dump();
  }

  // The same display from the rig model the daemon wrote: what every output draws.
  Calibrated cal;
  ASSERT_NO_FATAL_FAILURE(readCalibrated(dir.file("state"), kDomeOutputs, cal));
  auto master = render::domeMaster(kEye, Vec3(0, 1, 0), 180, {kSide, kSide});
  ASSERT_TRUE(master) << master.error().message;
  auto blend = blend::makeDomeBlend(cal.projectors, cal.responses, *master);
  ASSERT_TRUE(blend) << blend.error().message;
  const auto& lookup = blend->display.lookup;
  EXPECT_NEAR(display["dome"]["coverage"].get<double>(), blend->display.coverage, 1e-9);
  std::printf("[ figures  ] the projectors draw %.1f %% of the dome master's circle\n",
              100 * blend->display.coverage);
  // The three images lie 11 to 61 degrees from the zenith and meet around it: about a
  // third of the hemisphere's circle.
  EXPECT_GT(blend->display.coverage, 0.25);

  TrueRig true_rig{&*scene, {}};
  for (const auto& name : kDomeOutputs) true_rig.projectors.push_back(truth[name]);

  // Seams: where one projector puts a content point on the TRUE dome, the other shows
  // the same content point within 0.3 px RMS, 1 px at most (its pixels).
  const SeamFigures seams = seamsOnTheTrueSurface(lookup, true_rig, {kSide, kSide});
  ASSERT_GT(seams.pairs, 1000);
  std::printf("[ figures  ] seams: %d content points lit twice, RMS %.3f px, max %.3f px\n",
              seams.pairs, seams.rms, seams.worst);
  EXPECT_LE(seams.rms, 0.3);
  EXPECT_LE(seams.worst, 1.0);
  // The content lands in the direction the dome master gives it, seen from the eye:
  // within 0.5 content px, the bound a perspective display's straight lines are held to.
  const Placement placed = placedOnTheTrueDome(lookup, true_rig, *master);
  ASSERT_GT(placed.nodes, 1000);
  std::printf("[ figures  ] content placed on the dome: %d nodes, RMS %.3f, max %.3f content px\n",
              placed.nodes, placed.rms, placed.worst);
  EXPECT_LE(placed.worst, 0.5);

  // The frames: white through each output's lookup warp and blend, as the daemon drew
  // them (its statistics agree), lit by the TRUE projectors and seen from the eye looking
  // up (120 degrees) in linear light: no step above 2 % between neighbouring pixels where
  // the projectors draw, 3 % of the circle's diameter in from where they stop.
  sim::Framebuffers frames;
  for (std::size_t t = 0; t < 3; ++t) {
    frames[kDomeOutputs[t]] = whiteThroughLookup(lookup[t], *blend, t, {1280, 800}, {kSide, kSide},
                                                 shown[kDomeOutputs[t]], kDomeOutputs[t]);
  }
  auto lit = sim::Renderer::create(*scene, state, frames);
  ASSERT_TRUE(lit) << lit.error().message;
  geom::CameraModel up;  // at the eye, looking at the zenith, image x along world +X
  up.width = up.height = 600;
  up.K.fx = up.K.fy = 300 / std::tan(60 * M_PI / 180);
  up.K.cx = up.K.cy = 299.5;
  up.pose.R = Mat3::Identity();
  up.pose.t = -kEye;
  const cv::Mat view = lit->renderView(up, 4);
  // The master's pixels some TRUE projector lights through a drawn lookup cell, on a
  // 256 x 256 lattice, eroded by 3 % of the diameter.
  constexpr int kMask = 256;
  cv::Mat drawn(kMask, kMask, CV_8U, cv::Scalar(0));
  for (int y = 0; y < kMask; ++y) {
    for (int x = 0; x < kMask; ++x) {
      const auto dir =
          master->direction(Vec2((x + 0.5) * kSide / kMask - 0.5, (y + 0.5) * kSide / kMask - 0.5));
      if (!dir) continue;
      const auto hit = scene->world().intersect({kEye, *dir});
      if (!hit) continue;
      for (std::size_t m = 0; m < 3; ++m) {
        const auto q = true_rig.projectors[m].project(hit->hit.point);
        if (q && true_rig.inFrame(m, *q, 0) && render::gridSource(lookup[m], *q)) {
          drawn.at<std::uint8_t>(y, x) = 255;
          break;
        }
      }
    }
  }
  const int inset = static_cast<int>(std::lround(0.03 * kMask));
  cv::erode(drawn, drawn,
            cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * inset + 1, 2 * inset + 1}));
  auto inside = [&](int x, int y) {
    auto ray = up.backproject(Vec2(x, y));
    if (!ray) return false;
    auto hit = scene->world().intersect(*ray);
    if (!hit) return false;
    const auto cpx = master->contentPixel(hit->hit.point);
    if (!cpx) return false;
    const int mx = static_cast<int>((cpx->x() + 0.5) * kMask / kSide);
    const int my = static_cast<int>((cpx->y() + 0.5) * kMask / kSide);
    return mx >= 0 && my >= 0 && mx < kMask && my < kMask && drawn.at<std::uint8_t>(my, mx) != 0;
  };
  const ViewerLight light = viewerLight(view, inside);
  EXPECT_FALSE(light.unlit) << "an unlit point inside the display at pixel "
                            << light.unlit->transpose();
  std::printf(
      "[ figures  ] white seen from the eye: largest step %.2f %% at pixel (%.0f, %.0f), "
      "uniformity min/max %.3f over %ld pixels\n",
      100 * light.step, light.at.x(), light.at.y(), light.uniformity(), light.pixels);
  EXPECT_GT(light.pixels, 10000);
  EXPECT_LE(light.step, 0.02);
}

}  // namespace
}  // namespace procam::itest
