// The calibrate operation on the virtual rig, over the socket only: corner_stereo
// (two walls at 90 degrees, one projector, a stereo pair) at half resolution, so
// that the ray-cast captures take seconds.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "daemon_harness.hpp"
#include "rig/rig_model.hpp"
#include "sim/truth_rig.hpp"
#include "sim_calibrate_run.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

// A rig.json from an earlier calibration (the scene's cameras and a projector
// "old" on another output); returns its bytes.
std::string writePreviousRig(const TempDir& dir, const std::string& scene) {
  std::filesystem::create_directories(dir.path() + "/state");
  auto s = sim::resolveScene(scene);
  EXPECT_TRUE(s);
  auto rig = sim::truthRig(*s, 0.0);
  EXPECT_TRUE(rig);
  rig->projectors.at(0).name = rig->projectors.at(0).output = "old";
  rig->surface = {};
  const std::string previous = rig::rigToJson(*rig).dump(2) + "\n";
  dir.write("state/rig.json", previous);
  return previous;
}

// rig.json in the state directory, against the scene's truth, with the
// route (a) accuracy bounds on corner_stereo: focal 0.5%,
// principal point 2 px, position 2 mm, rotation 0.05 degrees, reprojection RMS
// <= 0.15 px.
void expectRigMatchesTruth(const TempDir& dir, const json& reply, const std::string& scene,
                           int projector_width) {
  const std::string path = reply["path"];
  EXPECT_EQ(path, dir.path() + "/state/rig.json");
  const json rig = json::parse(readFile(path));
  EXPECT_EQ(rig["version"], 2);
  const json* found = nullptr;
  for (const json& q : rig["projectors"]) {
    if (q["name"] == "proj") found = &q;
  }
  ASSERT_NE(found, nullptr) << rig.dump();
  const json& p = *found;
  EXPECT_EQ(p["output"], "proj");
  EXPECT_EQ(p["width"], projector_width);
  for (const char* key : {"K", "R", "t", "width", "height", "points"}) {
    EXPECT_EQ(p[key], reply["projector"][key]) << key;
  }
  EXPECT_NE(p["calibrated"]["method"].get<std::string>().find("route (a)"), std::string::npos);
  const geom::CameraModel truth = projectorTruth(scene);
  const double fx = p["K"][0], fy = p["K"][4], cx = p["K"][2], cy = p["K"][5];
  EXPECT_NEAR(fx, truth.K.fx, 0.005 * truth.K.fx);
  EXPECT_NEAR(fy, truth.K.fy, 0.005 * truth.K.fy);
  EXPECT_NEAR(cx, truth.K.cx, 2.0);
  EXPECT_NEAR(cy, truth.K.cy, 2.0);
  Mat3 R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = p["R"][i];
  const Vec3 t(p["t"][0], p["t"][1], p["t"][2]);
  const Vec3 position = -R.transpose() * t;
  const double position_mm = (position - truth.pose.center()).norm() * 1000;
  const double rotation_deg = Eigen::AngleAxisd(R.transpose() * truth.pose.R).angle() * 180 / M_PI;
  EXPECT_LT(position_mm, 2.0);
  EXPECT_LT(rotation_deg, 0.05);
  const double rms = reply["reprojection_rms_px"];
  EXPECT_LE(rms, 0.15);
  // Two walls: a mesh of the projector, written beside rig.json.
  EXPECT_EQ(reply["surface_type"], "mesh");
  EXPECT_EQ(rig["surface"], json({{"meshes", {{"proj", "surface-proj.ply"}}}}));
  EXPECT_EQ(readFile(dir.path() + "/state/surface-proj.ply").substr(0, 4), "ply\n");
  EXPECT_EQ(rig["cameras"].size(), 2u);
  std::printf(
      "[ figures  ] fx %.2f (truth %.2f, %.3f%%), fy %.2f (%.3f%%), cx %.2f (%+.2f px), "
      "cy %.2f (%+.2f px), position %.2f mm, rotation %.4f deg, RMS %.3f px, %d nodes\n",
      fx, truth.K.fx, 100 * (fx - truth.K.fx) / truth.K.fx, fy,
      100 * (fy - truth.K.fy) / truth.K.fy, cx, cx - truth.K.cx, cy, cy - truth.K.cy, position_mm,
      rotation_deg, rms, static_cast<int>(reply["triangulated"]));
}

// The scene's cameras handed over as calibrated (what procam-calibrate stereo gives);
// calibrate finds the projector and the surface.
DaemonProcess::Launch sim(const TempDir& dir, const std::string& scene) {
  return simWithTruth(dir, scene, TruthParts::kCamerasOnly);
}

// Waits for the operation's progress event with at least `captures` captures done.
bool waitForCaptures(Connection& c, CalibrateRun& run, int captures) {
  while (auto msg = c.next(60s)) {
    if ((*msg)["class"] != "EVENT" || (*msg)["event"] != "progress") continue;
    run.progress.push_back(*msg);
    if (static_cast<int>((*msg)["capture"]) >= captures) return true;
  }
  return false;
}

TEST(SimCalibrate, WritesRigJsonWithTheProjectorsIntrinsics) {
  TempDir dir;
  const std::string scene = sceneFile(dir);
  DaemonProcess d(dir, sim(dir, scene));
  ASSERT_TRUE(d.started()) << d.log();
  Connection watcher(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  Connection c(d.socketPath());
  auto started = c.call(calibrateRequest(1));
  CalibrateRun run;
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["state"], "started");
  const std::string op = (*started)["operation"];
  const int captures = (*started)["captures"];
  // gray+phase with 3 steps on 640x400 (Gray cell 8 px): white, black, 7 column and
  // 6 row Gray bits with their inverses, 3 phase frames per axis; two cameras.
  EXPECT_EQ((*started)["frames"], 34);
  EXPECT_EQ(captures, 68);
  follow(c, 1, run);
  ASSERT_TRUE(run.reply) << d.log();
  ASSERT_EQ((*run.reply)["class"], "CALIBRATE") << run.reply->dump();
  ASSERT_TRUE(run.finished);
  EXPECT_EQ((*run.finished)["ok"], true);
  EXPECT_EQ((*run.finished)["operation"], op);

  // Progress: one event per capture, in order, then decoding, solving, writing.
  int last_capture = 0, capturing = 0;
  double last_fraction = 0;
  std::set<std::string> stages;
  for (const json& e : run.progress) {
    capturing += e["stage"] == "capturing";
    EXPECT_EQ(e["operation"], op);
    EXPECT_GE(e["fraction"].get<double>(), last_fraction);
    EXPECT_GE(static_cast<int>(e["capture"]), last_capture);
    last_fraction = e["fraction"];
    last_capture = e["capture"];
    stages.insert(e["stage"].get<std::string>());
  }
  EXPECT_EQ(last_capture, captures);
  EXPECT_EQ(capturing, captures);
  // A watcher sees the same events.
  CalibrateRun watched;
  follow(watcher, -1, watched, 10s);
  ASSERT_TRUE(watched.finished);
  EXPECT_EQ((*watched.finished)["ok"], true);
  EXPECT_EQ(watched.progress.size(), run.progress.size());
  EXPECT_EQ(stages,
            (std::set<std::string>{"starting", "capturing", "decoding", "solving", "writing"}));

  expectRigMatchesTruth(dir, *run.reply, scene, 640);

  // The daemon is free again.
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["operations"], json::array());
}

// "mode": "adaptive" with the two calibrated cameras on the corner: the coarse pass (18
// frames, both cameras) finds the two walls not planar, and the full scan of route (a)
// follows (Gray code with 8 phase steps, 44 frames on 640x400), its captures added to the
// run's count. The projector is judged against the route (a) bounds above.
TEST(SimCalibrate, AnAdaptiveScanWithTwoCamerasScansACornerFully) {
  TempDir dir;
  const std::string scene = sceneFile(dir);
  DaemonProcess d(dir, sim(dir, scene));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  // Two cameras with a plane are cameras at several positions: not for the adaptive path.
  auto refused = c.call({{"cmd", "calibrate"},
                         {"mode", "adaptive"},
                         {"cameras", {"cam_left", "cam_right"}},
                         {"plane", {0.0, 1.0, 0.0, -3.0}}});
  ASSERT_TRUE(refused);
  EXPECT_EQ((*refused)["code"], "bad-argument") << refused->dump();
  auto started =
      c.call({{"cmd", "calibrate"}, {"id", 1}, {"mode", "adaptive"}, {"settle_frames", 0}});
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  EXPECT_EQ((*started)["mode"], "adaptive");
  EXPECT_EQ((*started)["route"], "a");
  EXPECT_EQ((*started)["frames"], 19);
  EXPECT_EQ((*started)["captures"], 38);
  CalibrateRun run;
  follow(c, 1, run, 300s);
  ASSERT_TRUE(run.reply) << d.log();
  ASSERT_EQ((*run.reply)["class"], "CALIBRATE") << run.reply->dump();
  const json& coarse = (*run.reply)["coarse"];
  std::printf("[ figures  ] adaptive on the corner, two cameras: %s\n", coarse.dump().c_str());
  EXPECT_FALSE(coarse["planar"].get<bool>());
  EXPECT_EQ(coarse["frames"], 18);
  EXPECT_EQ(coarse["full_frames"], 44);
  EXPECT_NE(coarse["then"].get<std::string>().find("not planar"), std::string::npos);
  EXPECT_EQ((*run.reply)["route"], "a");
  // Progress counts every capture, the full scan's after the coarse pass's.
  const int total = 2 * (18 + 44);
  int last = 0;
  double last_fraction = 0;
  for (const json& e : run.progress) {
    EXPECT_GE(e["capture"].get<int>(), last);
    EXPECT_GE(e["fraction"].get<double>(), last_fraction) << e.dump();
    last = e["capture"].get<int>();
    last_fraction = e["fraction"].get<double>();
  }
  EXPECT_LT(last_fraction, 1.0);
  EXPECT_EQ(last, total);
  ASSERT_FALSE(run.progress.empty());
  EXPECT_EQ(run.progress.back()["captures"], total);
  ASSERT_NO_FATAL_FAILURE(expectRigMatchesTruth(dir, *run.reply, scene, 640));
}

// The projector at its full 1280x800 with the cameras at 512x384: one camera pixel
// spans ~3.3 projector pixels, and the same tolerances hold.
// Also: the run merges into a rig that holds another projector and keeps it, and 3D
// content is then placed on the calibrated, non-planar surface (two walls).
TEST(SimCalibrate, CamerasCoarserThanTheProjector) {
  TempDir dir;
  const std::string scene = sceneFile(dir, 1.0);
  const std::string previous = writePreviousRig(dir, scene);
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", scene}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  writeContent(dir, "cube.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  auto before =
      c.call({{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "cube.obj")}}, 30s);
  ASSERT_TRUE(before);
  EXPECT_EQ((*before)["code"], "unavailable") << before->dump();  // no projector on 'proj' yet
  json reply;
  ASSERT_NO_FATAL_FAILURE(calibrateToTheEnd(c, d, &reply));
  expectRigMatchesTruth(dir, reply, scene, 1280);
  const json was = json::parse(previous);
  const json now = json::parse(readFile(dir.path() + "/state/rig.json"));
  ASSERT_EQ(now["projectors"].size(), 2u);
  EXPECT_EQ(now["projectors"][0], was["projectors"][0]);  // "old", untouched
  EXPECT_EQ(now["cameras"], was["cameras"]);
  // Two walls: 3D content stands on the plane through the surface point at the
  // projector's centre, facing the rig's viewer (the surface mesh is read after the reply).
  std::optional<json> after;
  ASSERT_TRUE(eventually(
      [&] {
        after = c.call(
            {{"cmd", "content"}, {"action", "load"}, {"path", contentFile(dir, "cube.obj")}}, 30s);
        return after && (*after)["class"] == "CONTENT";
      },
      10s))
      << (after ? after->dump() : "no reply");
  EXPECT_TRUE((*after)["content"]["mesh"]["placement"]["proj"].is_object()) << after->dump();
}

TEST(SimCalibrate, CancelMidRunKeepsThePreviousRigJson) {
  TempDir dir;
  const std::string scene = sceneFile(dir);
  const std::string previous = writePreviousRig(dir, scene);
  DaemonProcess d(dir, DaemonProcess::Launch{{"--sim", scene}, {}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto started = c.call(calibrateRequest(1));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  const std::string op = (*started)["operation"];
  CalibrateRun run;
  ASSERT_TRUE(waitForCaptures(c, run, 4));
  ASSERT_TRUE(c.send({{"cmd", "cancel"}, {"id", 2}, {"operation", op}}));
  std::optional<json> cancel_reply;
  while (auto msg = c.next(30s)) {
    if ((*msg)["class"] == "EVENT") {
      if ((*msg)["event"] == "finished") run.finished = *msg;
    } else if ((*msg)["id"] == 2) {
      cancel_reply = *msg;
    } else if ((*msg)["id"] == 1) {
      run.reply = *msg;
    }
    if (cancel_reply && run.reply && run.finished) break;
  }
  ASSERT_TRUE(cancel_reply);
  EXPECT_EQ((*cancel_reply)["cancelled"], json::array({op}));
  ASSERT_TRUE(run.reply);
  EXPECT_EQ((*run.reply)["class"], "ERROR");
  EXPECT_EQ((*run.reply)["code"], "cancelled");
  ASSERT_TRUE(run.finished);
  EXPECT_EQ((*run.finished)["ok"], false);
  // Stopped between frames, long before the last capture.
  EXPECT_LT(static_cast<int>(run.progress.back()["capture"]),
            static_cast<int>((*started)["captures"]));
  EXPECT_EQ(readFile(dir.path() + "/state/rig.json"), previous);
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/state/surface-proj.ply"));
  // A new calibration may start at once.
  auto again = c.call(calibrateRequest(3));
  ASSERT_TRUE(again);
  EXPECT_EQ((*again)["class"], "CALIBRATE") << again->dump();
}

// A camera unplugged mid-run (the mock drivers' PROCAM_SIM_UNPLUG window opens 4 s
// after the daemon started; half a second of settle per frame makes the 34-frame run
// last at least 17 s however fast the virtual camera lights it) cancels the operation
// with an error naming it; the device manager then lists it lost.
TEST(SimCalibrate, CameraGoneMidRunCancelsNamingIt) {
  TempDir dir;
  const std::string scene = sceneFile(dir);
  const std::string previous = writePreviousRig(dir, scene);
  DaemonProcess d(dir, {{"--sim", scene}, {"PROCAM_SIM_UNPLUG=cam_right@4-1000"}, -1, true});
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  json request = calibrateRequest(1);
  request["settle_frames"] = 30;  // 0.5 s at the mock output's 60 Hz
  auto started = c.call(request);
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  CalibrateRun run;
  follow(c, 1, run, 60s);
  ASSERT_TRUE(run.reply) << d.log();
  EXPECT_EQ((*run.reply)["class"], "ERROR");
  EXPECT_EQ((*run.reply)["code"], "cancelled");
  EXPECT_NE((*run.reply)["message"].get<std::string>().find("'cam_right'"), std::string::npos)
      << run.reply->dump();
  ASSERT_TRUE(run.finished);
  EXPECT_EQ((*run.finished)["ok"], false);
  EXPECT_EQ(readFile(dir.path() + "/state/rig.json"), previous);
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/state/surface-proj.ply"));
  auto devices = c.call({{"cmd", "devices"}});
  ASSERT_TRUE(devices);
  std::map<std::string, std::string> state;
  for (const auto& e : (*devices)["devices"]) state[e["name"]] = e["state"];
  EXPECT_EQ(state["cam_right"], "lost");
  EXPECT_EQ(state["cam_left"], "open");
}

TEST(SimCalibrate, SecondCalibrateWhileOneRunsIsBusy) {
  TempDir dir;
  DaemonProcess d(dir, sim(dir, sceneFile(dir)));
  ASSERT_TRUE(d.started()) << d.log();
  std::optional<Connection> first;
  first.emplace(d.socketPath());
  auto started = first->call(calibrateRequest(1));
  ASSERT_TRUE(started);
  ASSERT_EQ((*started)["class"], "CALIBRATE") << started->dump();
  const std::string op = (*started)["operation"];
  Connection second(d.socketPath());
  auto busy = second.call(calibrateRequest(7));
  ASSERT_TRUE(busy);
  EXPECT_EQ((*busy)["class"], "ERROR");
  EXPECT_EQ((*busy)["code"], "busy");
  EXPECT_EQ((*busy)["id"], 7);
  EXPECT_NE((*busy)["message"].get<std::string>().find(op), std::string::npos);
  // The second client's connection stays usable; the first operation still runs.
  auto status = second.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["operations"], json::array({{{"operation", op}, {"kind", "calibrate"}}}));
  // Closing the owner's connection cancels its operation.
  first.reset();
  EXPECT_TRUE(eventually(
      [&] {
        auto s = second.call({{"cmd", "status"}});
        return s && (*s)["operations"].empty();
      },
      30s));
}

TEST(SimCalibrate, MalformedArgumentsAreRefused) {
  TempDir dir;
  DaemonProcess d(dir, sim(dir, sceneFile(dir)));
  const std::string installed = readFile(dir.path() + "/state/rig.json");
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  const std::vector<json> bad = {
      {{"mode", "stripes"}},
      {{"mode", 3}},
      {{"step", 0}},
      {{"step", "2"}},
      {{"step", 1.5}},
      {{"grid", -8}},
      {{"settle_frames", 100000}},
      {{"phase_steps", 2}},
      {{"mode", "gray"}, {"phase_steps", 4}},
      {{"cameras", {"cam_left", "cam_left"}}},
      {{"cameras", {"a", "b", "c", "d", "e", "f", "g", "h", "i"}}},
      {{"cameras", {"cam_left", "cam_right", "cam_left"}}},
      {{"cameras", {""}}},
      {{"plane", {0, 0, 0, 1}}},
      {{"plane", {0, 1, 0}}},
      {{"plane", "wall"}},
      {{"cameras", {"cam_left", "cam_right"}}, {"board", "checker:9x6:0.03"}},
      {{"cameras", "cam_left"}},
      {{"output", ""}},
      {{"speed", "fast"}},
  };
  int id = 100;
  for (json args : bad) {
    args["cmd"] = "calibrate";
    args["id"] = ++id;
    auto r = c.call(args);
    ASSERT_TRUE(r) << args.dump();
    EXPECT_EQ((*r)["class"], "ERROR") << args.dump();
    EXPECT_EQ((*r)["code"], "bad-argument") << args.dump() << " -> " << r->dump();
    EXPECT_EQ((*r)["id"], id);
  }
  // Devices that do not exist: unavailable, naming them.
  auto r = c.call({{"cmd", "calibrate"}, {"cameras", {"cam_left", "cam_nope"}}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable");
  EXPECT_NE((*r)["message"].get<std::string>().find("cam_nope"), std::string::npos);
  r = c.call({{"cmd", "calibrate"}, {"output", "beamer"}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable");
  // One camera named is route (b′), which needs the display plane: the rig model
  // has none and the request gives none.
  r = c.call({{"cmd", "calibrate"}, {"cameras", {"cam_left"}}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["code"], "unavailable");
  EXPECT_NE((*r)["message"].get<std::string>().find("plane"), std::string::npos) << r->dump();
  auto status = c.call({{"cmd", "status"}});
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["operations"], json::array());
  EXPECT_EQ(readFile(dir.path() + "/state/rig.json"), installed);  // byte for byte
}

// The handheld rig has one camera: route (a) is unavailable there.
TEST(SimCalibrate, OneCameraIsUnavailable) {
  TempDir dir;
  DaemonProcess d(dir, sim(dir, "handheld"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto r = c.call({{"cmd", "calibrate"}});
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["class"], "ERROR");
  EXPECT_EQ((*r)["code"], "unavailable");
  EXPECT_NE((*r)["message"].get<std::string>().find("two"), std::string::npos);
}

}  // namespace
}  // namespace procam::itest
