// Automatic keystone and the output frames of procamd --sim, over the socket
// only. Ground truth comes from the scene: the projector's true rotation at the
// time of the tilt sample a solution was made from, solved with
// keystone::solveKeystone (procamd's keystone accuracy bounds: corner <= 0.5 px, aspect within
// 0.1 %, area within 0.5 % of the largest).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>

#include "daemon_harness.hpp"
#include "geometry/homography.hpp"
#include "keystone_truth.hpp"
#include "sim/embedded_scenes.hpp"
#include "sim/scene.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

// The scene's devices and, handed over explicitly, its truth as the rig model (the
// projector's intrinsics, the accelerometer's mount and six-position calibration).
DaemonProcess::Launch sim(const TempDir& dir, const std::string& scene) {
  return simWithTruth(dir, scene);
}

std::string handheldText() {
  for (std::size_t i = 0; i < sim::detail::kEmbeddedSceneCount; ++i) {
    if (sim::detail::kEmbeddedScenes[i].name == "handheld") {
      return std::string(sim::detail::kEmbeddedScenes[i].text);
    }
  }
  return {};
}

// The handheld scene with its hand motion replaced by two held poses (yaw 0:
// a tilt sensor sees pitch and roll only): A until t = 10 s, B from 11 s on.
constexpr double kHoldA = 10.0, kHoldB = 11.0;
std::string heldPosesScene() {
  std::string text = handheldText();
  const auto begin = text.find("[[trajectories]]");
  const auto end = text.find("\n]\n", begin);
  if (begin == std::string::npos || end == std::string::npos) return {};
  const std::string held = R"([[trajectories]]
name = "hand"
keyframes = [
  { t = 0.0, position = [0.0, 0.0, 1.2], pitch_deg = 20.0, roll_deg = -8.0 },
  { t = 10.0, position = [0.0, 0.0, 1.2], pitch_deg = 20.0, roll_deg = -8.0 },
  { t = 11.0, position = [0.0, 0.0, 1.2], pitch_deg = -14.0, roll_deg = 11.0 },
])";
  return text.substr(0, begin) + held + text.substr(end + 2);
}

// The handheld scene with the projector held level the whole time.
std::string levelScene() {
  std::string text = handheldText();
  const auto begin = text.find("[[trajectories]]");
  const auto end = text.find("\n]\n", begin);
  if (begin == std::string::npos || end == std::string::npos) return {};
  return text.substr(0, begin) +
         "[[trajectories]]\nname = \"hand\"\nkeyframes = [\n"
         "  { t = 0.0, position = [0.0, 0.0, 1.2] },\n]" +
         text.substr(end + 2);
}

TEST(SimKeystone, AutoKeystoneFollowsTheHeldPosesOfTheHandheldProjector) {
  TempDir dir;
  const std::string text = heldPosesScene();
  ASSERT_FALSE(text.empty());
  dir.write("held.toml", text);
  auto scene = sim::Scene::parse(text, "held.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;

  // The tilt sensor alone (the poses have no yaw): the camera on the projector, which
  // would show its dot grid at each hold, is test_sim_camera_yaw.cpp's.
  dir.write("procamd.toml", "[keystone]\ncamera_yaw = false\n");
  DaemonProcess::Launch launch = sim(dir, dir.file("held.toml"));
  launch.args.insert(launch.args.end(), {"--config", dir.file("procamd.toml")});
  DaemonProcess d(dir, launch);
  ASSERT_TRUE(d.started()) << d.log();
  Connection watcher(d.socketPath()), c(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  // A scene given by file does not turn auto keystone on by itself; the
  // accelerometer calibration may still be running, which is accepted.
  auto on = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();

  // Collect keystone events until one was made 7.5 s into hold B.
  std::optional<json> last_a, last_b;
  int updates_a_settled = 0;
  const auto deadline = std::chrono::steady_clock::now() + 40s;
  while (std::chrono::steady_clock::now() < deadline && !last_b) {
    auto e = watcher.next(2s);
    if (!e || (*e)["event"] != "keystone" || (*e)["mode"] != "auto") continue;
    const double t = (*e)["estimate"]["sample_time"].get<double>();
    if (t < kHoldA) last_a = *e;
    if (t > 3.0 && t < kHoldA) ++updates_a_settled;
    if (t > kHoldB + 7.5) last_b = *e;
  }
  ASSERT_TRUE(last_a && last_b) << d.log();
  ASSERT_GT((*last_a)["estimate"]["sample_time"].get<double>(), 4.0);

  for (const json* e : {&*last_a, &*last_b}) {
    const Measured m = handheldEventAgainstTruth(*scene, *e);
    std::printf("pose at t = %.2f s: corner %.3f px, aspect %.4f %%, area %.4f %%\n",
                (*e)["estimate"]["sample_time"].get<double>(), m.corner_px, 100 * m.aspect_rel,
                100 * m.area_rel);
    EXPECT_LE(m.corner_px, 0.5) << e->dump();
    EXPECT_LE(m.aspect_rel, 1e-3);
    EXPECT_LE(m.area_rel, 5e-3);
  }
  // Still holds re-solve only on the filter's refinements (after 2, 4, 8 s):
  // not once per sample (the sensor gave ~700 samples in that window).
  EXPECT_LE(updates_a_settled, 4);
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_GT((*status)["keystone"]["tilt"]["accepted"].get<int>(), 500);
}

TEST(SimKeystone, AutoOffStopsTheUpdates) {
  TempDir dir;
  dir.write("procamd.toml", "[policy]\nauto_keystone = true\n");
  DaemonProcess::Launch launch = sim(dir, "handheld");
  launch.args.insert(launch.args.end(), {"--config", dir.file("procamd.toml")});
  DaemonProcess d(dir, launch);  // auto keystone on by policy
  ASSERT_TRUE(d.started()) << d.log();
  Connection watcher(d.socketPath()), c(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  bool moving = false;
  for (int i = 0; i < 100 && !moving; ++i) {
    auto e = watcher.next(2s);
    moving = e && (*e)["event"] == "keystone" && (*e)["mode"] == "auto";
  }
  ASSERT_TRUE(moving) << d.log();
  auto off = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", false}});
  ASSERT_TRUE(off);
  EXPECT_EQ((*off)["auto"], false);
  EXPECT_EQ((*off)["mode"], "none");
  // Events already queued before the reply may still arrive; after the
  // watcher's own round trip none may be an auto update.
  ASSERT_TRUE(watcher.call({{"cmd", "version"}}));
  int late = 0;
  while (auto e = watcher.next(1500ms)) {
    if ((*e)["event"] == "keystone" && (*e)["mode"] == "auto") ++late;
  }
  EXPECT_EQ(late, 0);
}

// Area of a quad (shoelace) over the 1280x720 frame's.
double quadFraction(const std::array<Vec2, 4>& q) {
  double area2 = 0;
  for (int i = 0; i < 4; ++i)
    area2 += q[i].x() * q[(i + 1) % 4].y() - q[i].y() * q[(i + 1) % 4].x();
  return 0.5 * std::abs(area2) / (1280.0 * 720.0);
}

TEST(SimKeystone, TheTiltDriversRejectedSamplesShowInStatus) {
  TempDir dir;
  const std::string level = levelScene();
  ASSERT_FALSE(level.empty());
  // The same rig with a broken accelerometer: 2.5 g too much on its z (up) axis, clamped
  // at its 2 g full scale, so |f| is about 2 g for every sample and its driver's gate
  // drops them all (|f| outside [0.5, 1.5] g; the noise on x and y keeps them apart, so
  // none is a stuck repeat).
  std::string broken = level;
  const std::string bias = "bias_mg = [50.0, -50.0, 50.0]";
  const auto at = broken.find(bias);
  ASSERT_NE(at, std::string::npos);
  broken.replace(at, bias.size(), "bias_mg = [0.0, 0.0, 2500.0]");
  dir.write("level.toml", level);
  dir.write("broken.toml", broken);
  // The rig model is the healthy rig's (a broken sensor has no six-position fit).
  DaemonProcess::Launch launch{
      {"--sim", dir.file("broken.toml"), "--rig", truthRigFile(dir, dir.file("level.toml"))},
      {},
      -1,
      true};
  DaemonProcess d(dir, launch);
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_TRUE(eventually([&] {
    auto on = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", true}});
    return on && (*on)["class"] == "KEYSTONE";
  }));
  std::optional<json> status;
  ASSERT_TRUE(eventually(
      [&] {
        status = c.call({{"cmd", "status"}});
        if (!status) return false;
        const json r = status->value(json::json_pointer("/keystone/tilt/rejected"), json());
        return r.is_number() && r.get<int>() >= 50;
      },
      20s))
      << (status ? status->dump() : "no reply");
  const json& tilt = (*status)["keystone"]["tilt"];
  EXPECT_EQ(tilt["accepted"].get<int>(), 0) << tilt.dump();
  EXPECT_EQ(tilt["rejected_by"]["bad_norm"].get<int>(), tilt["rejected"].get<int>());
  EXPECT_EQ(tilt["rejected_by"]["stuck"].get<int>(), 0);
  EXPECT_EQ(tilt["rejected_by"]["not_finite"].get<int>(), 0);
  EXPECT_EQ(tilt["rejected_by"]["out_of_range"].get<int>(), 0);
  // Nothing reached the filter: no solution.
  EXPECT_FALSE((*status)["keystone"].contains("estimate")) << status->dump();
}

TEST(SimKeystone, SixPositionCalibrationStepsOverTheSocket) {
  TempDir dir;
  dir.write("level.toml", levelScene());
  DaemonProcess d(dir, sim(dir, dir.file("level.toml")));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  // Without auto keystone nothing reads the sensor.
  auto early = c.call({{"cmd", "keystone"}, {"action", "accel-sample"}});
  ASSERT_TRUE(early);
  EXPECT_EQ((*early)["code"], "unavailable");
  ASSERT_TRUE(eventually([&] {
    auto on = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", true}});
    return on && (*on)["class"] == "KEYSTONE";
  }));
  // Still for over a second: the level projector has the chip's z axis up
  // (handheld.toml's mount).
  std::optional<json> sample;
  ASSERT_TRUE(eventually(
      [&] {
        sample = c.call({{"cmd", "keystone"}, {"action", "accel-sample"}});
        return sample && (*sample)["class"] == "KEYSTONE";
      },
      10s))
      << (sample ? sample->dump() : "no reply");
  const json& cal = (*sample)["accel_calibration"];
  EXPECT_EQ(cal["pose"], "+z");
  EXPECT_EQ(cal["filled"], json({"+z"}));
  EXPECT_EQ(cal["missing"].size(), 5u);
  // The raw mean carries the scene's +50 mg bias on z: 1.05 g within noise.
  EXPECT_NEAR(cal["mean_g"][2].get<double>(), 1.05, 2e-3);
  auto solve = c.call({{"cmd", "keystone"}, {"action", "accel-solve"}});
  ASSERT_TRUE(solve);
  EXPECT_EQ((*solve)["code"], "bad-argument");
  EXPECT_NE((*solve)["message"].get<std::string>().find("+x, -x, +y, -y, -z"), std::string::npos)
      << solve->dump();
  auto reset = c.call({{"cmd", "keystone"}, {"action", "accel-reset"}});
  ASSERT_TRUE(reset);
  EXPECT_TRUE((*reset)["accel_calibration"]["filled"].empty());
}

// A version 1 rig.json in the state directory (one projector, no output binding)
// gives the intrinsics; the mount comes from the configuration's defaults.
TEST(SimKeystone, IntrinsicsComeFromTheRigModel) {
  TempDir dir;
  ::mkdir(dir.file("state").c_str(), 0750);
  dir.write("state/rig.json",
            R"({"cameras": [], "projectors": [{"name": "proj", "width": 1280, "height": 720,
                "K": [1500, 0, 640, 0, 1490, 360, 0, 0, 1], "R": [1,0,0,0,1,0,0,0,1],
                "t": [0, 0, 0]}]})");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", "handheld"}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  json k;
  ASSERT_TRUE(eventually([&] {
    k = *c.call({{"cmd", "keystone"}});
    return k.contains("projector");
  }));
  EXPECT_EQ(k["projector"]["intrinsics"], json({1500.0, 1490.0, 640.0, 360.0}));
  EXPECT_EQ(k["projector"]["source"], "rig model (rig.json)");
}

json outputStats(Connection& c) {
  auto s = c.call({{"cmd", "status"}});
  if (!s || (*s)["outputs"]["shown"].empty()) return nullptr;
  return (*s)["outputs"]["shown"][0];
}

TEST(SimKeystone, KeystoneSetGetAndWhatTheOutputShows) {
  TempDir dir;
  DaemonProcess d(dir, sim(dir, "handheld"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_EQ((*c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", false}}))["class"],
            "KEYSTONE");

  // Unwarped white: every pixel lit. Black: none.
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "white"}}))["shown"], true);
  json st = outputStats(c);
  EXPECT_EQ(st["source"], "pattern:white");
  EXPECT_DOUBLE_EQ(st["lit_fraction"].get<double>(), 1.0);
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "black"}}))["shown"], true);
  EXPECT_DOUBLE_EQ(outputStats(c)["lit_fraction"].get<double>(), 0.0);

  // A manual homography: set, read back, and the white frame covers its quad.
  Mat3 H;
  H << 0.8, 0.05, 100, -0.02, 0.75, 60, 1e-5, -2e-5, 1;
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({H(r, 0), H(r, 1), H(r, 2)});
  auto set = c.call({{"cmd", "keystone"}, {"action", "set"}, {"homography", rows}});
  ASSERT_TRUE(set);
  ASSERT_EQ((*set)["class"], "KEYSTONE") << set->dump();
  EXPECT_EQ((*set)["mode"], "manual");
  auto get = c.call({{"cmd", "keystone"}});
  const Mat3 back = matrixOf((*get)["homography"]);
  EXPECT_LT((back - H).cwiseAbs().maxCoeff(), 1e-7) << get->dump();
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "white"}}))["shown"], true);
  // Lit pixel centres inside the quad of the content's outer edges: off by at
  // most the share of its boundary pixels.
  EXPECT_NEAR(outputStats(c)["lit_fraction"].get<double>(),
              quadFraction(outerCorners(H, 1280, 720)), 4e-3);

  // Content: a red image, shown through the same warp when the pattern is off.
  const std::string png = contentFile(dir, "red.png");
  cv::imwrite(png, cv::Mat(180, 320, CV_8UC3, cv::Scalar(0, 0, 255)));  // BGR
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "off"}}))["pattern"], "off");
  auto load = c.call({{"cmd", "content"}, {"action", "load"}, {"path", png}});
  ASSERT_TRUE(load);
  ASSERT_EQ((*load)["class"], "CONTENT") << load->dump();
  json shown;
  ASSERT_TRUE(eventually([&] {
    shown = outputStats(c);
    return shown.is_object() && shown["source"] == "content";
  }));
  // The stored corners hold the content's corner pixel centres; its outer edges
  // lie half a content pixel further out.
  const json corners = (*c.call({{"cmd", "keystone"}}))["corners"];
  std::array<Vec2, 4> dst;
  for (int i = 0; i < 4; ++i)
    dst[i] = Vec2(corners[i][0].get<double>(), corners[i][1].get<double>());
  auto Hc = geom::homographyFrom4({Vec2(0, 0), Vec2(319, 0), Vec2(319, 179), Vec2(0, 179)}, dst);
  ASSERT_TRUE(Hc);
  const double lit = shown["lit_fraction"].get<double>();
  EXPECT_NEAR(lit, quadFraction(outerCorners(*Hc, 320, 180)), 4e-3);
  EXPECT_NEAR(shown["mean_rgb"][0].get<double>(), 255 * lit, 1.0);
  EXPECT_EQ(shown["mean_rgb"][1].get<double>(), 0.0);
  EXPECT_EQ(shown["mean_rgb"][2].get<double>(), 0.0);

  // Nothing moves: no new frames.
  auto frames = [&] { return (*c.call({{"cmd", "status"}}))["outputs"]["frames"].get<int>(); };
  const int before = frames();
  std::this_thread::sleep_for(1s);
  EXPECT_EQ(frames(), before);

  ASSERT_TRUE(c.call({{"cmd", "content"}, {"action", "clear"}}));
  ASSERT_TRUE(eventually([&] { return outputStats(c)["source"] == "none"; }));
  EXPECT_EQ(outputStats(c)["lit_fraction"].get<double>(), 0.0);
}

}  // namespace
}  // namespace procam::itest
