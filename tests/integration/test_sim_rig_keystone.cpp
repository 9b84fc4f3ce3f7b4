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

#include "daemon_harness.hpp"
#include "keystone_truth.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"

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

// The final reply to `id` (CALIBRATE done or ERROR), skipping events.
std::optional<json> finalReply(Connection& c, int id, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout * kSlowdown;
  while (std::chrono::steady_clock::now() < deadline) {
    auto msg = c.next(std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now()));
    if (!msg) return std::nullopt;
    if ((*msg)["class"] != "EVENT" && (*msg)["id"] == id && (*msg)["state"] != "started") {
      return msg;
    }
  }
  return std::nullopt;
}

// Lit framebuffer share of the quad (shoelace) over the w x h frame.
double quadFraction(const std::array<Vec2, 4>& q, int w, int h) {
  double area2 = 0;
  for (int i = 0; i < 4; ++i)
    area2 += q[i].x() * q[(i + 1) % 4].y() - q[i].y() * q[(i + 1) % 4].x();
  return 0.5 * std::abs(area2) / (double(w) * h);
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

  const auto t0 = std::chrono::steady_clock::now();
  auto started = c.call(calibrateRequest(1, kWallPlane));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["route"], "b'");
  EXPECT_EQ((*started)["cameras"], json({"cam"}));
  auto done = finalReply(c, 1, 240s);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(done) << d.log();
  ASSERT_EQ((*done)["class"], "CALIBRATE") << done->dump();
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

  auto on = c.call({{"cmd", "keystone"}, {"action", "rig"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();
  EXPECT_EQ((*on)["mode"], "rig");
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["keystone"]["mode"], "rig");

  // Nothing loaded: the content is the output's 1920x1080; then a 4:3 image.
  const std::string png = dir.file("slide.png");
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

  // The plane is in the rig model now: with its one camera, calibrate takes route
  // (b′) by itself, keeps the plane as it is and the keystone follows.
  const json plane_before = rig["surface"];
  auto again = c.call(calibrateRequest(2, nullptr));
  ASSERT_TRUE(again);
  ASSERT_EQ((*again)["class"], "CALIBRATE") << again->dump();
  EXPECT_EQ((*again)["route"], "b'");
  auto redone = finalReply(c, 2, 240s);
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

}  // namespace
}  // namespace procam::itest
