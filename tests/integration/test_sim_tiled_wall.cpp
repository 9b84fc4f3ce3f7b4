// Four projectors on one flat wall shown as one display, end to end on the virtual
// rig over the socket only: tiled_wall (2x2 projectors of 1280x800 with unmatched
// responses, two cameras) with nothing handed over but the cameras' calibration
// (TruthParts::kCamerasOnly) and the wall's plane as an installer measures it.
// calibrate (route b′) maps each projector onto the wall, `keystone rig on` makes one
// display of them ([Raskar02] §4.2.4) with feathered overlaps (eq. 4.3), and the
// homographies the outputs draw with are judged with the TRUE projectors and wall.
#include <gtest/gtest.h>

#include "keystone_truth.hpp"
#include "tiled_wall_checks.hpp"

namespace procam::itest {
namespace {

TEST(SimTiledWall, FourProjectorsCalibratedIntoOneSeamlessDisplay) {
  auto scene = sim::resolveScene("tiled_wall");
  ASSERT_TRUE(scene) << scene.error().message;
  const sim::SceneState state = scene->at(0);
  std::map<std::string, geom::CameraModel> truth;
  std::map<std::string, sim::ProjectorSpec> spec;
  for (const auto& p : state.projectors) {
    truth[p.spec.name] = p.model;
    spec[p.spec.name] = p.spec;
  }
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "tiled_wall", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Malformed projector lists are refused before anything is shown.
  for (const json& bad : {json::array(), json({"proj_tl", "proj_tl"}), json("some"), json(7)}) {
    auto r = c.call({{"cmd", "calibrate"}, {"projectors", bad}, {"plane", kWallPlane}});
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["code"], "bad-argument") << bad.dump() << " " << r->dump();
    EXPECT_NE((*r)["message"].get<std::string>().find("\"projectors\" must be"), std::string::npos)
        << r->dump();
  }
  auto both = c.call({{"cmd", "calibrate"}, {"projectors", "all"}, {"output", "proj_tl"}});
  ASSERT_TRUE(both);
  EXPECT_EQ((*both)["code"], "bad-argument") << both->dump();
  EXPECT_NE((*both)["message"].get<std::string>().find("either"), std::string::npos)
      << both->dump();

  // Every projector, one after the other, through the camera that sees the whole wall;
  // one rig model written at the end.
  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call(calibrateEveryProjector(json({"cam_a"})));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["outputs"], json({"proj_tl", "proj_tr", "proj_bl", "proj_br"}));
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  ASSERT_EQ((*done)["outputs"].size(), 4u) << done->dump();
  for (const json& o : (*done)["outputs"]) {
    std::printf("[ figures  ] %s: collineation RMS %.4f projector px, %d nodes\n",
                o["output"].get<std::string>().c_str(),
                o["homography"]["rms_projector_px"].get<double>(),
                o["homography"]["inliers"].get<int>());
    // Gray + phase decodes within 0.1 projector px RMS (ARCHITECTURE.md).
    EXPECT_LT(o["homography"]["rms_projector_px"].get<double>(), 0.15);
    // The response from the grey ramp, through a linear camera: its mean over some
    // 100k pixels at levels of 5-170 units fixes gamma to about 0.01; 0.05 allowed.
    const std::string name = o["output"].get<std::string>();
    const double gamma = o["response"]["response_gamma"].get<double>();
    std::printf("[ figures  ] %s: response gamma %.4f (true %.1f), white %.1f, black %.2f\n",
                name.c_str(), gamma, spec[name].gamma, o["response"]["white"].get<double>(),
                o["response"]["black"].get<double>());
    EXPECT_NEAR(gamma, spec[name].gamma, 0.05) << name;
  }
  EXPECT_EQ((*done)["rig"]["projectors"], 4);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Every image overlaps every other in the middle of the wall: one projector at a time.
  EXPECT_EQ((*done)["scan"]["batches"].size(), 4u) << done->dump();
  std::printf("[ figures  ] four projectors calibrated in %.1f s (%d captures, %zu scan batches)\n",
              seconds, (*done)["scan"]["captures"].get<int>(), (*done)["scan"]["batches"].size());

  // A 16:9 white slide on the one display.
  constexpr int kW = 1600, kH = 900;
  const std::string png = contentFile(dir, "slide.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255))));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, 30s);
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();

  // Every output draws its tile of the display.
  json display;
  std::map<std::string, Mat3> H = tiles(c, kW, kH, 4, display);
  ASSERT_EQ(H.size(), 4u) << display.dump() << "\n" << d.log();
  EXPECT_EQ(display["outputs"].size(), 4u);
  // Matched per pixel: every projector's white across its frame, measured by cam_a at
  // calibration, is the TRUE brightness cos θ / d² times one factor (the camera's units
  // and the wall's albedo) within 2 %: each node averages over 100 camera pixels (noise
  // 0.1 %); nodes within two of the frame's edge, where the camera's blur and the
  // fill-in from seen neighbours reach, are not judged.
  EXPECT_EQ(display["blend"]["response"], "measured") << display.dump();
  const json& matching = display["blend"]["photometric"];
  ASSERT_EQ(matching["matching"], "per-pixel") << display.dump();
  std::printf(
      "[ figures  ] matching: uniformity %.3f before, %.3f after, light kept %.3f, "
      "largest target step %.4f %% per content px\n",
      matching["uniformity_before"].get<double>(), matching["uniformity_after"].get<double>(),
      matching["light_kept"].get<double>(), 100 * matching["largest_step_per_px"].get<double>());
  for (const json& t : display["tiles"]) EXPECT_EQ(t["gain"].get<double>(), 1.0);
  std::ifstream written(dir.file("state/rig.json"));
  auto calibrated = rig::rigFromJson(json::parse(written, nullptr, false), "rig.json");
  ASSERT_TRUE(calibrated) << calibrated.error().message;
  std::vector<double> ratios;
  std::map<std::string, blend::BrightnessMap> maps;
  for (const auto& p : calibrated->projectors) {
    auto r = blend::projectorResponse(p);
    ASSERT_TRUE(r && r->brightness) << p.name << ": " << p.photometric.dump();
    maps[p.name] = *r->brightness;
  }
  for (const auto& [name, map] : maps) {
    for (int j = 2; j + 2 < map.white.rows; ++j) {
      for (int i = 2; i + 2 < map.white.cols; ++i) {
        const Vec2 px(i * map.step, j * map.step);
        ratios.push_back(map.white.at<float>(j, i) / trueWhite(spec[name], truth[name], px));
      }
    }
  }
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  const double factor = ratios[ratios.size() / 2];
  double worst = 0;
  for (double q : ratios) worst = std::max(worst, std::abs(q / factor - 1));
  std::printf(
      "[ figures  ] brightness maps: %zu interior nodes within %.2f %% of the true "
      "fall-off and brightness\n",
      ratios.size(), 100 * worst);
  EXPECT_LE(worst, 0.02);

  // Seams: within 0.3 px RMS, 1 px at most (ARCHITECTURE.md).
  const Seams seams = seamsOnTheTruth(H, truth, kW, kH);
  ASSERT_GT(seams.pairs, 1000);
  EXPECT_LE(seams.rms, 0.3);
  EXPECT_LE(seams.max, 1.0);

  // The display on the TRUE wall: its corners through a projector that shows them.
  auto wallPoint = [&](const Vec2& content) -> std::optional<Vec3> {
    for (const char* a : kOutputs) {
      const Vec2 p = (H[a] * content.homogeneous()).hnormalized();
      if (inFrame(truth[a], p, -1)) return onTheWall(truth[a], p);
    }
    return std::nullopt;
  };
  const auto tl = wallPoint({-0.5, -0.5}), tr = wallPoint({kW - 0.5, -0.5}),
             bl = wallPoint({-0.5, kH - 0.5}), br = wallPoint({kW - 0.5, kH - 0.5});
  ASSERT_TRUE(tl && tr && bl && br) << "a corner of the display is not lit";
  const Vec3 top = *tr - *tl, left = *tl - *bl;
  const double tilt_deg = std::atan2(top.z(), top.x()) * kDegPerRad;
  const double lean_deg = std::atan2(left.x(), left.z()) * kDegPerRad;
  const double aspect = top.norm() / left.norm() / (double(kW) / kH) - 1;
  const double area =
      0.5 * ((*tr - *tl).cross(*bl - *tl).norm() + (*tr - *br).cross(*bl - *br).norm());
  // The optimum from the TRUE footprints.
  std::vector<blend::DisplayTile> tiles;
  const geom::Plane wall{Vec3(0, 1, 0), -3};
  auto basis = geom::uprightBasis(wall, Vec3(0, 0, 1.5), Vec3(0, 3, 1.5));
  ASSERT_TRUE(basis);
  for (const char* a : kOutputs) {
    auto to_image = geom::planeToImage(truth[a].K, truth[a].pose, *basis);
    ASSERT_TRUE(to_image);
    tiles.push_back({{*basis, to_image->inverse()}, truth[a].width, truth[a].height});
  }
  auto optimum =
      blend::solveTiledDisplay(tiles, kW, kH, {.raster_cells = 2048, .rect = {}, .world_rect = {}});
  ASSERT_TRUE(optimum) << optimum.error().message;
  const double of_optimum = area / optimum->rect.area();
  std::printf(
      "[ figures  ] display %.3f x %.3f m: top edge %.4f deg off level, side %.4f deg off "
      "plumb, aspect %+.4f %%, area %.2f %% of the optimum from the true footprints\n",
      top.norm(), left.norm(), tilt_deg, lean_deg, 100 * aspect, 100 * of_optimum);
  EXPECT_LE(std::abs(tilt_deg), 0.05);
  EXPECT_LE(std::abs(lean_deg), 0.05);
  EXPECT_LE(std::abs(aspect), 1e-3);
  EXPECT_GE(of_optimum, 0.98);

  // Luminance: the daemon's white on the wall, through the camera in linear light, has
  // no step above 2 % between neighbouring blocks over the display (a seam would step
  // by the overlap's error). For scale: the same display drawn with the assumed gamma
  // 2.2 and no matching, seen from the viewer.
  const Reported rep = reported(display, H);
  const Luminance before = unmatchedWhiteSeenByTheViewer(*scene, state, rep, kW, kH);
  const Luminance after = whiteSeenByTheCamera(c, state, rep, "cam_a");
  std::printf(
      "[ figures  ] white through cam_a: largest step %.2f %% between 12 px blocks at camera "
      "pixel (%.0f, %.0f), uniformity min/max %.3f (assumed gamma 2.2, no matching, seen "
      "from the viewer: step %.2f %% between pixels, uniformity %.3f)\n",
      100 * after.step, after.at.x(), after.at.y(), after.uniformity, 100 * before.step,
      before.uniformity);
  EXPECT_LE(after.step, 0.02);
  EXPECT_GT(after.uniformity, 0.5);
  EXPECT_LE(of_optimum, 1.0 + 2 * 4 * optimum->cell_m / left.norm());
}

// While one projector is calibrated every other output shows black: with all four
// showing white before, a neighbour left white would saturate the camera where it
// overlaps the scanned image (~20-25 % of it) and those nodes would not decode. The
// camera sees the whole wall, so all but the frame's edge nodes decode (95 % of the
// 160 x 100 nodes of an 8 px grid asked), and the response ramp at level 0 sees only
// the ambient light (the scene's 0.02 against a projector's 9-13 at 2 m: under 1 % of
// its white).
TEST(SimTiledWall, OtherOutputsAreBlackWhileOneIsCalibrated) {
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "tiled_wall", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto white = c.call({{"cmd", "pattern"}, {"name", "white"}});
  ASSERT_TRUE(white && (*white)["shown"] == true) << (white ? white->dump() : "none");
  const json request = {{"cmd", "calibrate"},  {"id", 1},
                        {"output", "proj_tl"}, {"cameras", {"cam_a"}},
                        {"plane", kWallPlane}, {"mode", "gray+phase"},
                        {"phase_steps", 3},    {"grid", 8},
                        {"settle_frames", 0},  {"response", true}};
  auto started = c.call(request);
  ASSERT_TRUE(started && (*started)["class"] == "CALIBRATE")
      << (started ? started->dump() : "none");
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  const double black = (*done)["response"]["black"].get<double>();
  const double level = (*done)["response"]["white"].get<double>();
  std::printf(
      "[ figures  ] proj_tl alone, the others black: response black %.2f, white %.1f "
      "(%.2f %%); %d of %d nodes, collineation RMS %.4f px\n",
      black, level, 100 * black / level, (*done)["homography"]["inliers"].get<int>(),
      (*done)["homography"]["samples"].get<int>(),
      (*done)["homography"]["rms_projector_px"].get<double>());
  EXPECT_LT(black, 0.02 * level);
  EXPECT_GE((*done)["homography"]["samples"].get<int>(), 0.95 * (1280 / 8) * (800 / 8));
}

// Two calibrated cameras and no plane: route (a) finds the wall coplanar (no projection
// matrix follows from a plane), triangulates it instead and takes route (b′) on it.
// With Gray codes alone the pair triangulates a node to about 2 mm RMS; over the
// ~4,000 nodes of one projector the fitted plane's noise averages out (0.03 mm), and
// 1 mm and 0.05 degrees leave room for the bias all nodes share (Gray codes decode
// cell centres).
TEST(SimTiledWall, TwoCamerasOnThePlanarWallTakeThePlaneTheyTriangulate) {
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "tiled_wall", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  // Gray codes alone on a 16 px grid: the fewest captures that still give thousands of
  // nodes (the plane is what is judged here, not the decoding's resolution).
  const json request = {
      {"cmd", "calibrate"}, {"id", 1},    {"output", "proj_tl"}, {"cameras", {"cam_a", "cam_b"}},
      {"mode", "gray"},     {"grid", 16}, {"settle_frames", 0}};
  auto started = c.call(request);
  ASSERT_TRUE(started && (*started)["class"] == "CALIBRATE")
      << (started ? started->dump() : "none");
  EXPECT_EQ((*started)["route"], "a");
  auto done = finalReply(c, 1, 600s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  EXPECT_EQ((*done)["route"], "b'");
  EXPECT_EQ((*done)["plane_source"], "cameras");
  const json& plane = (*done)["surface"]["plane"];
  ASSERT_EQ(plane.size(), 4u) << done->dump();
  const auto [angle_deg, offset_mm] = planeOffTheWall(plane, 3.0);
  std::printf(
      "[ figures  ] proj_tl, two cameras, no plane: wall triangulated from %d nodes "
      "(RMS %.3f mm), normal %.4f deg and %.3f mm off the truth; collineation RMS %.4f px\n",
      (*done)["triangulated_plane"]["inliers"].get<int>(),
      1000 * (*done)["triangulated_plane"]["rms_m"].get<double>(), angle_deg, offset_mm,
      (*done)["homography"]["rms_projector_px"].get<double>());
  EXPECT_LT(angle_deg, 0.05);
  EXPECT_LT(offset_mm, 1.0);
  // The plane is the rig's surface now, and the projector has its collineation.
  std::ifstream in(dir.file("state/rig.json"));
  const json rig = json::parse(in, nullptr, false);
  ASSERT_TRUE(rig.is_object());
  EXPECT_EQ(rig["surface"]["plane"], plane);
  ASSERT_EQ(rig["projectors"].size(), 1u);
  EXPECT_TRUE(rig["projectors"][0].contains("plane_homography"));
}

// A display rectangle from the configuration ([keystone] display_centre, display_size:
// world metres) instead of the largest one, on the true rig handed over explicitly (its
// projectors have intrinsics and poses and the wall is a plane: each one's collineation
// with the wall follows from them).
TEST(SimTiledWall, ConfiguredDisplayRectangleIsUsed) {
  TempDir dir;
  dir.write("procamd.toml",
            "[keystone]\ndisplay_centre = [0.1, 3.0, 1.45]\ndisplay_size = [1.6, 0.9]\n");
  auto launch = simWithTruth(dir, "tiled_wall");
  launch.args.insert(launch.args.end(), {"--config", dir.file("procamd.toml")});
  DaemonProcess d(dir, launch);
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  const std::string png = contentFile(dir, "slide.png");
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(450, 800, CV_8UC3, cv::Scalar(255, 255, 255))));
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}}, 30s);
  ASSERT_TRUE(load && (*load)["class"] == "CONTENT") << (load ? load->dump() : "none");
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on && (*on)["class"] == "KEYSTONE") << (on ? on->dump() : "none");
  json display;
  ASSERT_TRUE(eventually(
      [&] {
        auto s = c.call({{"cmd", "status"}});
        display = s ? (*s)["keystone"].value("display", json()) : json();
        return display.is_object() && display.value("state", "") == "ready";
      },
      30s))
      << display.dump() << "\n"
      << d.log();
  EXPECT_EQ(display["rect_source"], "config");
  EXPECT_EQ(display["outputs"].size(), 4u);
  EXPECT_NEAR(display["rect_m"]["size"][0].get<double>(), 1.6, 1e-9);
  EXPECT_NEAR(display["rect_m"]["size"][1].get<double>(), 0.9, 1e-9);
  const json& b = display["basis"];
  Vec3 centre = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    centre[i] = b["origin"][i].get<double>() +
                display["rect_m"]["centre"][0].get<double>() * b["u"][i].get<double>() +
                display["rect_m"]["centre"][1].get<double>() * b["v"][i].get<double>();
  }
  EXPECT_NEAR((centre - Vec3(0.1, 3.0, 1.45)).norm(), 0, 1e-9) << centre.transpose();
}

}  // namespace
}  // namespace procam::itest
