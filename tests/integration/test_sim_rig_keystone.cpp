// Keystone of a calibrated planar wall, end to end on the virtual rig, over the
// socket only: wall_oblique (one 1920x1080 projector at 30 degrees yaw and 15
// degrees pitch to the wall y = 3, one camera) with nothing handed over but what an
// installer has beforehand: the camera's calibration (TruthParts::kCamerasOnly, as
// procam-calibrate gives it) and the wall's plane, measured in the world frame the
// cameras were calibrated in. calibrate (route b′) writes the projector's
// collineation with the wall into rig.json; `keystone rig on` shows the content
// through it; the frame is judged with the TRUE projector against the keystone
// accuracy bounds (ARCHITECTURE.md: corner <= 0.5 px, aspect within 0.1 %, area
// within 0.5 % of the largest upright rectangle inside the true footprint).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "daemon_harness.hpp"
#include "keystone_truth.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"
#include "unit/drift/second_camera.hpp"

namespace procam::itest {
namespace {

// The wall of wall_oblique.toml: the plane y = 3 (a x + b y + c z + d = 0), as the
// installer has it when the cameras' world frame was set up on the wall
// ([Raskar02] §4.2.5 lets the screen define the world frame). The keystone does
// not depend on the plane's offset (camera rays meet parallel planes in similar
// figures); its normal matters: measured here, 1 degree off turns the corners
// 8.7 px away.
const json kWallPlane = {0.0, 1.0, 0.0, -3.0};

// Gray code + 3-step phase, nodes every 8 projector pixels, no settle wait (the
// mock output shows a frame at once): the request of the SimCalibrate tests; the
// plane given, or (null) the rig model's.
json calibrateRequest(int id, const json& plane) {
  json r = {{"cmd", "calibrate"}, {"id", id},  {"mode", "gray+phase"},
            {"phase_steps", 3},   {"grid", 8}, {"settle_frames", 0}};
  if (!plane.is_null()) r["plane"] = plane;
  return r;
}

// Lit framebuffer share of the quad (shoelace) over the w x h frame.
double quadFraction(const std::array<Vec2, 4>& q, int w, int h) {
  double area2 = 0;
  for (int i = 0; i < 4; ++i)
    area2 += q[i].x() * q[(i + 1) % 4].y() - q[i].y() * q[(i + 1) % 4].x();
  return 0.5 * std::abs(area2) / (double(w) * h);
}

// Runs route (b′) with `request` (id 1) to its final reply and checks the
// collineation's fit; nullopt (with failures) when it does not finish.
std::optional<json> calibrateOnTheWall(Connection& c, const DaemonProcess& d, const json& request) {
  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call(request);
  EXPECT_TRUE(started);
  if (!started) return std::nullopt;
  EXPECT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["route"], "b'");
  EXPECT_EQ((*started)["cameras"], json({"cam"}));
  if ((*started)["class"] != "CALIBRATE") return std::nullopt;
  auto done = finalReply(c, request["id"].get<int>(), 480s);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(done) << d.log();
  if (!done) return std::nullopt;
  EXPECT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  if ((*done)["class"] != "CALIBRATE") return std::nullopt;
  const json& fit = (*done)["homography"];
  std::printf(
      "[ figures  ] calibrate %.1f s (%d captures), collineation RMS %.4f camera px / %.4f "
      "projector px, %d of %d nodes, coverage %.1f %%, condition %.3g\n",
      seconds, (*started)["captures"].get<int>(), fit["rms_camera_px"].get<double>(),
      fit["rms_projector_px"].get<double>(), fit["inliers"].get<int>(), fit["samples"].get<int>(),
      100 * fit["coverage"].get<double>(), fit["condition"].get<double>());
  // Gray + phase decodes within 0.1 projector px RMS per axis (ARCHITECTURE.md); the
  // collineation's residuals cannot exceed the decoding's.
  EXPECT_LT(fit["rms_projector_px"].get<double>(), 0.15);
  return done;
}

// `keystone rig on`, then the frame the rig's keystone shows judged with the TRUE
// projector for the output's own size and for a 4:3 image: the content's corners on
// the wall against the largest upright rectangle inside the true footprint.
void keystoneFromTheRigMatchesTruth(Connection& c, const TempDir& dir,
                                    const geom::CameraModel& truth) {
  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();
  EXPECT_EQ((*on)["mode"], "rig");
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["keystone"]["mode"], "rig");

  // Nothing loaded: the content is the output's 1920x1080; then a 4:3 image.
  const std::string png = contentFile(dir, "slide.png");
  cv::imwrite(png, cv::Mat(600, 800, CV_8UC3, cv::Scalar(255, 255, 255)));
  for (int round = 0; round < 2; ++round) {
    if (round == 1) {
      auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}});
      ASSERT_TRUE(load);
      ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
      ASSERT_TRUE(eventually([&] {
        auto k = c.call({{"cmd", "keystone"}});
        return k && (*k)["content_size"] == json({800, 600});
      }));
    }
    auto k = c.call({{"cmd", "keystone"}});
    ASSERT_TRUE(k);
    ASSERT_EQ((*k)["mode"], "rig") << k->dump();
    const int cw = (*k)["content_size"][0], ch = (*k)["content_size"][1];
    const Mat3 H = matrixOf((*k)["homography"]);
    const Measured m =
        measureAgainstTruth(truth.K, truth.pose.R, truth.width, truth.height, H, cw, ch);
    std::printf("[ figures  ] content %dx%d: corner %.3f px, aspect %.4f %%, area %.4f %%\n", cw,
                ch, m.corner_px, 100 * m.aspect_rel, 100 * m.area_rel);
    EXPECT_LE(m.corner_px, 0.5) << k->dump();
    EXPECT_LE(m.aspect_rel, 1e-3);
    EXPECT_LE(m.area_rel, 5e-3);
    if (round == 0) {
      // What the output shows: white through that warp lights the quad of the
      // content's outer edges (up to the share of its boundary pixels).
      ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "white"}}))["shown"], true);
      auto st = c.call({{"cmd", "status"}});
      ASSERT_TRUE(st);
      const json& shown = (*st)["outputs"]["shown"][0];
      EXPECT_NEAR(shown["lit_fraction"].get<double>(),
                  quadFraction(outerCorners(H, cw, ch), truth.width, truth.height), 2e-3);
      ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "off"}}))["pattern"], "off");
    }
  }
}

TEST(SimRigKeystone, CalibratedPlanarWallKeystonesFromTheRig) {
  auto scene = sim::resolveScene("wall_oblique");
  ASSERT_TRUE(scene) << scene.error().message;
  const geom::CameraModel truth = scene->at(0).projectors.at(0).model;
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "wall_oblique", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Nothing in the rig maps the projector onto the wall yet.
  auto early = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(early);
  EXPECT_EQ((*early)["code"], "unavailable") << early->dump();
  // One camera and no plane anywhere: route (b′) needs the plane.
  auto no_plane = c.call({{"cmd", "calibrate"}});
  ASSERT_TRUE(no_plane);
  EXPECT_EQ((*no_plane)["code"], "unavailable") << no_plane->dump();

  auto done = calibrateOnTheWall(c, d, calibrateRequest(1, kWallPlane));
  ASSERT_TRUE(done);
  // rig.json: the plane as given, and the projector's collineation with it (no K).
  std::ifstream rig_file((*done)["path"].get<std::string>());
  const json rig = json::parse(rig_file, nullptr, false);
  EXPECT_EQ(rig["surface"]["plane"], kWallPlane);
  ASSERT_EQ(rig["projectors"].size(), 1u);
  const json& p = rig["projectors"][0];
  EXPECT_EQ(p["output"], "proj");
  EXPECT_FALSE(p.contains("K"));
  ASSERT_TRUE(p.contains("plane_homography"));
  EXPECT_EQ(p["plane_homography"], (*done)["projector"]["plane_homography"]);

  ASSERT_NO_FATAL_FAILURE(keystoneFromTheRigMatchesTruth(c, dir, truth));

  // The plane is in the rig model now: with its one camera, calibrate takes route
  // (b′) by itself, keeps the plane as it is and the keystone follows.
  const json plane_before = rig["surface"];
  auto again = c.call(calibrateRequest(2, nullptr));
  ASSERT_TRUE(again);
  ASSERT_EQ((*again)["class"], "CALIBRATE") << again->dump();
  EXPECT_EQ((*again)["route"], "b'");
  auto redone = finalReply(c, 2, 480s);
  ASSERT_TRUE(redone) << d.log();
  ASSERT_EQ((*redone)["class"], "CALIBRATE") << redone->dump();
  EXPECT_EQ((*redone)["plane_source"], "rig");
  std::ifstream rig_again((*redone)["path"].get<std::string>());
  EXPECT_EQ(json::parse(rig_again, nullptr, false)["surface"], plane_before);
  auto k = c.call({{"cmd", "keystone"}});
  ASSERT_TRUE(k);
  EXPECT_EQ((*k)["mode"], "rig");

  // A manual correction replaces the rig's.
  auto manual = c.call({{"cmd", "keystone"},
                        {"action", "set"},
                        {"corners", {{10, 10}, {1900, 20}, {1890, 1070}, {5, 1060}}}});
  ASSERT_TRUE(manual);
  EXPECT_EQ((*manual)["mode"], "manual");
  EXPECT_EQ((*manual)["rig"], false);
}

// The single-frame path: one frame of AprilTags and one capture instead of the Gray-code
// sequence, with the camera's calibration and the wall's plane as above; the tag corners
// fix the projector's collineation with the wall, and the keystone from it is judged
// with the true projector against the same bounds.
TEST(SimRigKeystone, OneTagFrameCalibratesThePlanarWall) {
  auto scene = sim::resolveScene("wall_oblique");
  ASSERT_TRUE(scene) << scene.error().message;
  const geom::CameraModel truth = scene->at(0).projectors.at(0).model;
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "wall_oblique", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  // Gray-code arguments and a response ramp have no meaning for one tag frame.
  for (const json& bad : {json{{"cmd", "calibrate"}, {"mode", "apriltag"}, {"step", 4}},
                          json{{"cmd", "calibrate"}, {"mode", "apriltag"}, {"response", true}},
                          json{{"cmd", "calibrate"}, {"mode", "apriltags"}}}) {
    auto r = c.call(bad);
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["code"], "bad-argument") << r->dump();
  }
  const json request = {{"cmd", "calibrate"},
                        {"id", 1},
                        {"mode", "apriltag"},
                        {"plane", kWallPlane},
                        {"settle_frames", 0}};
  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call(request);
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["route"], "b'");
  EXPECT_EQ((*started)["mode"], "apriltag");
  EXPECT_EQ((*started)["frames"], 1);
  EXPECT_EQ((*started)["captures"], 1);
  auto done = finalReply(c, 1, 120s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const json& fit = (*done)["homography"];
  std::printf(
      "[ figures  ] one tag frame: calibrate %.2f s, %d tag corners found, collineation RMS "
      "%.4f camera px / %.4f projector px, %d of %d corners, coverage %.1f %%\n",
      seconds, (*done)["decoded"][0].get<int>(), fit["rms_camera_px"].get<double>(),
      fit["rms_projector_px"].get<double>(), fit["inliers"].get<int>(), fit["samples"].get<int>(),
      100 * fit["coverage"].get<double>());
  EXPECT_EQ(fit["inliers"], fit["samples"]);
  ASSERT_NO_FATAL_FAILURE(keystoneFromTheRigMatchesTruth(c, dir, truth));
}

// "mode": "adaptive" with only the camera's calibration given: the coarse Gray pass (16x12
// blocks, 18 frames) finds wall_oblique planar and one tag frame finishes, 19 frames in
// all, the keystone from it as from the full scan; on corner_stereo (two walls meeting
// in a corner, one camera named) the same pass finds the surface not planar and the
// calibration is refused, the rig model left without a projector.
TEST(SimRigKeystone, AnAdaptiveScanStopsAtOneTagFrameOnAPlaneAndRefusesACorner) {
  {
    auto scene = sim::resolveScene("wall_oblique");
    ASSERT_TRUE(scene) << scene.error().message;
    TempDir dir;
    DaemonProcess d(dir, simWithTruth(dir, "wall_oblique", TruthParts::kCamerasOnly));
    ASSERT_TRUE(d.started()) << d.log();
    Connection c(d.socketPath());
    auto bad = c.call({{"cmd", "calibrate"}, {"mode", "adaptive"}, {"grid", 8}});
    ASSERT_TRUE(bad);
    EXPECT_EQ((*bad)["code"], "bad-argument") << bad->dump();
    const auto t0 = std::chrono::steady_clock::now();
    auto started = c.call({{"cmd", "calibrate"},
                           {"id", 1},
                           {"mode", "adaptive"},
                           {"plane", kWallPlane},
                           {"settle_frames", 0}});
    ASSERT_TRUE(started);
    ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
    EXPECT_EQ((*started)["mode"], "adaptive");
    EXPECT_EQ((*started)["frames"], 19);
    EXPECT_EQ((*started)["captures"], 19);
    auto done = finalReply(c, 1, 480s);
    ASSERT_TRUE(done) << d.log();
    ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const json& coarse = (*done)["coarse"];
    std::printf(
        "[ figures  ] adaptive on wall_oblique: calibrate %.1f s, coarse pass %d frames, %d "
        "blocks fit one homography to %.3f projector px (a plane allows %.3f); tag frame: "
        "collineation %.4f projector px RMS\n",
        seconds, coarse["frames"].get<int>(), coarse["blocks"].get<int>(),
        coarse["rms_px"].get<double>(), coarse["tolerance_px"].get<double>(),
        (*done)["homography"]["rms_projector_px"].get<double>());
    EXPECT_TRUE(coarse["planar"].get<bool>()) << done->dump();
    EXPECT_EQ(coarse["frames"], 18);
    ASSERT_NO_FATAL_FAILURE(
        keystoneFromTheRigMatchesTruth(c, dir, scene->at(0).projectors.at(0).model));
  }
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "corner_stereo", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto started = c.call({{"cmd", "calibrate"},
                         {"id", 2},
                         {"mode", "adaptive"},
                         {"cameras", {"cam_left"}},
                         {"plane", {0.0, 1.0, 0.0, -3.0}},
                         {"settle_frames", 0}});
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  auto done = finalReply(c, 2, 480s);
  ASSERT_TRUE(done) << d.log();
  std::printf("[ figures  ] adaptive on corner_stereo: %s\n",
              done->value("message", std::string()).c_str());
  EXPECT_EQ((*done)["code"], "failed") << done->dump();
  EXPECT_NE(done->value("message", std::string()).find("not planar"), std::string::npos)
      << done->dump();
  // Nothing written: rig.json still holds the cameras alone.
  std::ifstream rig_file(dir.file("state/rig.json"));
  const json rig = json::parse(rig_file, nullptr, false);
  ASSERT_TRUE(rig.is_object());
  EXPECT_TRUE(!rig.contains("projectors") || rig["projectors"].empty()) << rig.dump();
}

// "mode": "adaptive" with two calibrated cameras and no plane (wall_oblique with a second
// camera 1.5 m to the right of the first): the coarse pass finds the wall planar in both
// cameras, and the tag frame's corners that both find triangulate its plane, so the
// projector takes route (b′) on it after 19 frames. The wall's normal must be good to
// 0.05 degrees (1 degree turns the keystone's corners 8.7 px; they are allowed 0.5 px)
// and its offset to 1 mm; then the keystone is judged as above.
TEST(SimRigKeystone, AnAdaptiveScanWithTwoCamerasTriangulatesThePlanarWall) {
  TempDir dir;
  std::ifstream in(std::string(std::getenv("PROCAM_SOURCE_DIR") ?: ".") +
                   "/tests/scenes/wall_oblique.toml");
  std::stringstream text;
  text << in.rdbuf();
  ASSERT_FALSE(text.str().empty()) << "PROCAM_SOURCE_DIR must name the source tree";
  dir.write("wall_two_cameras.toml", text.str() + "\n" + drift::kSecondCamera);
  const std::string scene_file = dir.file("wall_two_cameras.toml");
  auto scene = sim::resolveScene(scene_file);
  ASSERT_TRUE(scene) << scene.error().message;
  DaemonProcess d(dir, simWithTruth(dir, scene_file, TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call({{"cmd", "calibrate"},
                         {"id", 1},
                         {"mode", "adaptive"},
                         {"cameras", {"cam", "cam2"}},
                         {"settle_frames", 0}});
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["mode"], "adaptive");
  EXPECT_EQ((*started)["frames"], 19);
  EXPECT_EQ((*started)["captures"], 38);
  auto done = finalReply(c, 1, 480s);
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ((*done)["route"], "b'");
  EXPECT_EQ((*done)["plane_source"], "cameras");
  const json& coarse = (*done)["coarse"];
  EXPECT_TRUE(coarse["planar"].get<bool>()) << done->dump();
  ASSERT_EQ(coarse["views"].size(), 2u) << done->dump();
  EXPECT_FALSE(coarse.contains("then")) << done->dump();
  const json& plane = (*done)["surface"]["plane"];
  ASSERT_EQ(plane.size(), 4u) << done->dump();
  const auto [angle_deg, offset_mm] = planeOffTheWall(plane, 3.0);
  std::printf(
      "[ figures  ] adaptive, two cameras, no plane: calibrate %.1f s; tag corners %d and %d, "
      "plane from %d (RMS %.3f mm), normal %.4f deg and %.3f mm off the truth; collineation "
      "%.4f projector px RMS\n",
      seconds, (*done)["decoded"][0].get<int>(), (*done)["decoded"][1].get<int>(),
      (*done)["triangulated_plane"]["inliers"].get<int>(),
      1000 * (*done)["triangulated_plane"]["rms_m"].get<double>(), angle_deg, offset_mm,
      (*done)["homography"]["rms_projector_px"].get<double>());
  EXPECT_LT(angle_deg, 0.05);
  EXPECT_LT(offset_mm, 1.0);
  ASSERT_NO_FATAL_FAILURE(
      keystoneFromTheRigMatchesTruth(c, dir, scene->at(0).projectors.at(0).model));
}

// Nothing from truth but the camera's calibration: the wall is found from a board
// fixed on it (wall_oblique_board: a checkerboard of 9x6 inner corners, 12 cm squares,
// lit by the white frame of the calibration sequence; [Raskar02] §4.2.4 needs the
// screen plane and the board gives it), then the keystone is judged as above. The
// wall's normal must be good to 0.05 degrees: measured above, 1 degree of normal turns
// the corners 8.7 px, and the keystone allows 0.5 px. Its offset does not move the
// keystone; the board's scale gives it to 1 mm (0.05 px over a board 330 px wide at
// 3.6 m), 5 mm allowed.
TEST(SimRigKeystone, WallFoundFromABoardOnItKeystonesFromTheRig) {
  auto scene = sim::resolveScene("wall_oblique_board");
  ASSERT_TRUE(scene) << scene.error().message;
  const geom::CameraModel truth = scene->at(0).projectors.at(0).model;
  TempDir dir;
  DaemonProcess d(dir, simWithTruth(dir, "wall_oblique_board", TruthParts::kCamerasOnly));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());

  // Malformed boards are refused before anything is shown.
  for (const json& bad : {json("aprilgrid:6x4"), json("poster:6x4:0.15"), json(42),
                          json("aprilgrid:100000x100000:0.15"), json("checker:9x6:1e9")}) {
    json request = calibrateRequest(5, nullptr);
    request["board"] = bad;
    auto r = c.call(request);
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["code"], "bad-argument") << r->dump();
  }
  json both = calibrateRequest(6, kWallPlane);
  both["board"] = "checker:9x6:0.12";
  auto r = c.call(both);
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "bad-argument") << r->dump();

  // A board that is not on the wall ends the run at the first (white) frame.
  json wrong = calibrateRequest(7, nullptr);
  wrong["board"] = "checker:7x5:0.12";
  auto wrong_started = c.call(wrong);
  ASSERT_TRUE(wrong_started);
  ASSERT_EQ((*wrong_started)["class"], "CALIBRATE") << wrong_started->dump();
  auto wrong_done = finalReply(c, 7, 60s);
  ASSERT_TRUE(wrong_done) << d.log();
  EXPECT_EQ((*wrong_done)["code"], "failed") << wrong_done->dump();
  EXPECT_NE((*wrong_done)["message"].get<std::string>().find("does not see the board checker:7x5"),
            std::string::npos)
      << wrong_done->dump();
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_TRUE((*status)["operations"].empty()) << status->dump();

  json request = calibrateRequest(1, nullptr);
  request["board"] = "checker:9x6:0.12";
  auto done = calibrateOnTheWall(c, d, request);
  ASSERT_TRUE(done);
  EXPECT_EQ((*done)["plane_source"], "board");
  const json& board = (*done)["board"];
  ASSERT_TRUE(board.is_object()) << done->dump();
  const json plane = (*done)["surface"]["plane"];
  ASSERT_EQ(plane.size(), 4u) << done->dump();
  const Vec3 n(plane[0].get<double>(), plane[1].get<double>(), plane[2].get<double>());
  const double normal_deg = std::acos(std::min(1.0, n.normalized().y())) * 180 / M_PI;
  const double offset_m = std::abs(plane[3].get<double>() / n.norm() + 3.0);
  std::printf(
      "[ figures  ] board: %d points, RMS %.3f px, incidence %.1f deg; wall normal "
      "%.4f deg, offset %.2f mm off the true wall\n",
      board["points"].get<int>(), board["rms_px"].get<double>(),
      board["incidence_deg"].get<double>(), normal_deg, 1000 * offset_m);
  EXPECT_EQ(board["points"].get<int>(), 54);  // every inner corner
  EXPECT_LE(normal_deg, 0.05);
  EXPECT_LE(offset_m, 0.005);
  // rig.json holds the plane found.
  std::ifstream rig_file((*done)["path"].get<std::string>());
  const json rig = json::parse(rig_file, nullptr, false);
  EXPECT_EQ(rig["surface"]["plane"], plane);
  ASSERT_EQ(rig["projectors"].size(), 1u);
  EXPECT_NE(rig["projectors"][0]["calibrated"]["method"].get<std::string>().find("board"),
            std::string::npos)
      << rig["projectors"][0].dump();

  ASSERT_NO_FATAL_FAILURE(keystoneFromTheRigMatchesTruth(c, dir, truth));
}

}  // namespace
}  // namespace procam::itest
