// recalibrate = "on-drift" end to end on the virtual rig: wall_oblique (one 1920x1080
// projector at 30 deg yaw / 15 deg pitch to a wall, one fixed camera with 0.8 DN read
// noise) with its truth at rest as the rig model and textured content shown through
// `keystone rig on`; scene events bump the projector while the daemon runs. The
// corrected rig is judged against the TRUE bumped projector: where its framebuffer
// pixels land on the wall, and the keystone's corners (ARCHITECTURE.md: corner
// <= 0.5 px, aspect within 0.1 %, area within 0.5 %).
#include "sim_drift_rig.hpp"

namespace procam::itest {
namespace {

TEST(SimDrift, ABumpedProjectorIsCorrectedFromTheContentWithoutAScan) {
  // Still for 8 s (about thirty checks), then bumped 0.5 degrees, then 2 degrees more.
  const Bump bumps[] = {{at(8.0), 0.5, 0.0}, {at(18.0), 0.0, -2.0}};
  TempDir dir;
  std::string events;
  for (const Bump& b : bumps) {
    events += "[[events]]\nt = " + std::to_string(b.t) + "\ntarget = \"proj\"\nrotate_deg = [" +
              std::to_string(b.yaw) + ", " + std::to_string(b.pitch) + ", 0.0]\n\n";
  }
  const std::string scene_file = sceneWithEvents(dir, events);
  auto scene = sim::resolveScene(scene_file);
  ASSERT_TRUE(scene) << scene.error().message;
  DaemonProcess d(dir, driftDaemon(dir, "on-drift", scene_file));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  Connection watcher(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  const auto started = daemonStart(c);
  ASSERT_NO_FATAL_FAILURE(showContent(c, texturedContent(dir)));
  const auto sceneTime = [&] {
    return std::chrono::duration<double>(Clock::now() - started).count();
  };

  // At rest: registered, no correction.
  ASSERT_TRUE(checkedTimes([&] { return outputDrift(c); }, 3, 6s))
      << outputDrift(c).dump() << d.log();
  for (std::size_t i = 0; i < std::size(bumps); ++i) {
    const Bump& b = bumps[i];
    SCOPED_TRACE(testing::Message() << "bump " << i + 1);
    // Until the bump: nothing to correct.
    double rest_worst = 0;
    while (sceneTime() < b.t - 0.3) {
      const json dr = outputDrift(c);
      ASSERT_TRUE(dr.is_object());
      EXPECT_EQ(dr["state"], "registered") << dr.dump();
      if (dr.contains("misregistration_px")) {
        rest_worst = std::max(rest_worst, dr["misregistration_px"].get<double>());
      }
      std::this_thread::sleep_for(200ms);
    }
    const json at_rest = outputDrift(c);
    EXPECT_LT(rest_worst, 0.25) << at_rest.dump();  // half the threshold: no false trigger
    EXPECT_EQ(at_rest["corrections"], i) << at_rest.dump();

    std::optional<double> detected, corrected, registered;
    double detect_capture = 0, register_capture = 0;  // those checks' captures
    json correction;
    const auto deadline = Clock::now() + 15s * kSlowdown;
    while (Clock::now() < deadline && !registered) {
      auto e = watcher.next(1s);
      if (!e || (*e)["event"] != "drift") continue;
      const double t = sceneTime() - b.t;
      const std::string state = (*e)["state"];
      if (state == "detected" && !detected) {
        detected = t;
        detect_capture = (*e)["timing"]["capture_s"].get<double>();
      }
      if (state == "corrected-pose") {
        corrected = t;
        correction = *e;
      }
      if (state == "corrected") {
        registered = t;
        register_capture = (*e)["timing"]["capture_s"].get<double>();
      }
      EXPECT_NE(state, "unresolved") << e->dump();
      EXPECT_NE(state, "failed") << e->dump();
    }
    ASSERT_TRUE(detected && corrected && registered) << d.log();
    const geom::CameraModel truth = scene->at(b.t + at(1.0)).projectors.at(0).model;
    const double rig_px = rigAgainstTruth(dir, truth);
    const Measured m = keystoneAgainstTruth(c, truth);
    const json dr = outputDrift(c);
    std::printf(
        "[ figures  ] bump %.1f deg yaw %.1f deg pitch: at rest before it <= %.3f px; "
        "detected after %.2f s (of it %.2f s the virtual camera's capture), corrected after %.2f "
        "s (pass %d, %d tiles), registered after %.2f s (%.2f s capture) at %.3f px; the rig "
        "against the true projector %.3f px, keystone "
        "corner %.3f px, aspect %.4f %%, area %.4f %%; last check %.0f ms (reference %.0f, capture "
        "%.0f, registration %.0f)\n",
        b.yaw, b.pitch, rest_worst, *detected, detect_capture, *corrected,
        correction["pass"].get<int>(), correction["tiles"].get<int>(), *registered,
        register_capture, dr.value("misregistration_px", -1.0), rig_px, m.corner_px,
        100 * m.aspect_rel, 100 * m.area_rel, 1000 * dr.value("check_s", 0.0),
        1000 * dr.value("reference_s", 0.0), 1000 * dr.value("capture_s", 0.0),
        1000 * dr.value("measure_s", 0.0));
    // The scene's clock starts after the daemon's: these times are upper bounds. The
    // virtual camera ray-casts the bumped scene when it captures (0.4 s on two idle
    // cores, over a second when they are busy; a real camera delivers a frame in one
    // frame period): detection is bounded without that render time.
    EXPECT_LE(*detected - detect_capture, 1.0 * kSlowdown);
    EXPECT_LE(*registered - detect_capture - register_capture, 5.0 * kSlowdown);
    EXPECT_EQ(correction["step"], "projector-pose");
    EXPECT_LE(rig_px, 0.5);
    EXPECT_LE(m.corner_px, 0.5);
    EXPECT_LE(m.aspect_rel, 1e-3);
    EXPECT_LE(m.area_rel, 5e-3);
  }
  // No scan ran: no calibrate operation, the content stayed on.
  auto st = c.call({{"cmd", "status"}});
  ASSERT_TRUE(st);
  EXPECT_TRUE((*st)["operations"].empty());
  EXPECT_EQ((*st)["outputs"]["shown"][0]["source"], "content");
  // procamctl says it in a line per output.
  const RunResult ctl = runProgram({PROCAMCTL_BIN, "--socket", d.socketPath(), "status"});
  EXPECT_EQ(ctl.status, 0) << ctl.err;
  EXPECT_NE(ctl.out.find("recalibrate:   on-drift"), std::string::npos) << ctl.out;
  EXPECT_NE(ctl.out.find("drift proj:    registered"), std::string::npos) << ctl.out;
  EXPECT_NE(ctl.out.find("2 correction(s)"), std::string::npos) << ctl.out;
}

// The camera unplugged after a bump was detected and before its settle time ran out
// (PROCAM_SIM_UNPLUG, seconds after the daemon started): no correction is made from the
// older check, the rig model stays byte for byte; when the camera is back the checks
// resume and correct the projector.
TEST(SimDrift, ACameraUnpluggedAfterDriftWasSeenLeavesTheRigUntilItIsBack) {
  TempDir dir;
  const std::string scene_file =
      sceneWithEvents(dir, "[[events]]\nt = " + atText(5.0) +
                               "\ntarget = \"proj\"\nrotate_deg = [0.0, 1.0, 0.0]\n");
  auto scene = sim::resolveScene(scene_file);
  ASSERT_TRUE(scene) << scene.error().message;
  DaemonProcess d(dir, driftDaemon(dir, "on-drift", scene_file,
                                   {"PROCAM_SIM_UNPLUG=cam@" + atText(8.0) + "-" + atText(11.0)},
                                   "drift_settle_s = " + atText(4.0) + "\n"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  Connection watcher(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  const auto started = daemonStart(c);
  const std::string before = rigText(dir);
  ASSERT_NO_FATAL_FAILURE(showContent(c, texturedContent(dir)));
  const auto sceneTime = [&] {
    return std::chrono::duration<double>(Clock::now() - started).count();
  };
  std::optional<double> detected;
  while (sceneTime() < at(10.0)) {
    auto e = watcher.next(250ms);
    if (!e || (*e)["event"] != "drift") continue;
    if ((*e)["state"] == "detected" && !detected) detected = sceneTime();
    EXPECT_NE((*e)["state"], "corrected-pose") << e->dump();
  }
  // Seen before the camera went (at 8 s), not corrected while it is gone.
  ASSERT_TRUE(detected) << d.log();
  EXPECT_LT(*detected, at(8.0));
  const json gone = outputDrift(c);
  ASSERT_TRUE(gone.is_object()) << d.log();
  EXPECT_EQ(gone.value("corrections", 0), 0) << gone.dump();
  // The camera's absence seen: by a check that failed on it, or, when the device manager
  // closed it first (a busy machine), by no check running without it.
  EXPECT_TRUE(gone.value("failures", 0) >= 1 ||
              gone.value("unavailable", "").find("no open") != std::string::npos)
      << gone.dump();
  EXPECT_EQ(before, rigText(dir));
  // Back at 11 s: checked again and corrected.
  ASSERT_TRUE(eventually(
      [&] {
        const json dr = outputDrift(c);
        return dr.value("corrections", 0) >= 1 && dr.value("state", "") == "registered";
      },
      15s * kSlowdown))
      << outputDrift(c).dump() << d.log();
  const double rig_px = rigAgainstTruth(dir, scene->at(at(6.0)).projectors.at(0).model);
  std::printf(
      "[ figures  ] drift seen at %.2f s, the camera gone %.0f-%.0f s, corrected after it came "
      "back: the rig against the true projector %.3f px\n",
      *detected, at(8.0), at(11.0), rig_px);
  EXPECT_LE(rig_px, 0.5);
}

// Two fixed cameras, one of them bumped: the other still sees the content where the rig
// puts it, so the bumped camera is re-registered and the projector left as it is; then the
// projector bumped, which both cameras see.
TEST(SimDrift, ABumpedCameraIsReregisteredAndTheProjectorLeftAlone) {
  TempDir dir;
  DriftRig r(dir, "[[events]]\nt = " + atText(6.0) +
                      "\ntarget = \"cam\"\nrotate_deg = [0.3, 0.0, 0.0]\n\n"
                      "[[events]]\nt = " +
                      atText(16.0) + "\ntarget = \"proj\"\nrotate_deg = [0.5, 0.0, 0.0]\n");
  ASSERT_NO_FATAL_FAILURE(r.start(dir));
  auto [scene, d, c, watcher] = std::tie(r.scene, r.d, r.c, r.watcher);
  const auto projectorOf = [&] {
    auto rig = rig::rigFromText(rigText(dir), "rig.json");
    return rig ? rig::rigToJson(*rig)["projectors"] : json(nullptr);
  };
  const json projector_before = projectorOf();
  bool registered = false;
  const std::optional<json> corrected =
      awaitCorrection(watcher, "corrected-camera", "corrected-pose", registered);
  ASSERT_TRUE(corrected) << outputDrift(c).dump() << d.log();
  EXPECT_EQ((*corrected)["camera"], "cam");
  EXPECT_EQ((*corrected)["step"], "camera-pose");
  EXPECT_TRUE(registered) << outputDrift(c).dump();
  EXPECT_EQ(projector_before, projectorOf());
  // The re-registered camera against the true bumped one, over the content on the wall
  // (what the camera watches, where the pose is fitted: the keystone's rectangle).
  auto k = c.call({{"cmd", "keystone"}});
  ASSERT_TRUE(k && (*k)["mode"] == "rig");
  const Mat3 H = matrixOf((*k)["homography"]);
  const int cw = (*k)["content_size"][0], ch = (*k)["content_size"][1];
  auto rig = rig::rigFromText(rigText(dir), "rig.json");
  ASSERT_TRUE(rig) << rig.error().message;
  const geom::CameraModel truth = scene->at(at(7.0)).cameras.at(0).model;
  const geom::CameraModel projector = scene->at(at(7.0)).projectors.at(0).model;
  const rig::RigCamera* fixed = rig->camera("cam");
  ASSERT_TRUE(fixed);
  double worst = 0;
  int seen = 0;
  for (int y = 0; y < ch; y += 30) {
    for (int x = 0; x < cw; x += 30) {
      const Vec3 f = H * Vec3(x, y, 1.0);
      auto ray = projector.backproject(f.head<2>() / f.z());
      auto hit = ray ? geom::intersectPlane(*ray, *rig->surface.plane) : std::nullopt;
      auto want = hit ? truth.project(hit->point) : std::nullopt;
      if (!want || !truth.inImage(*want)) continue;
      auto back = fixed->model.project(hit->point);
      ASSERT_TRUE(back);
      worst = std::max(worst, (*back - *want).norm());
      ++seen;
    }
  }
  ASSERT_GT(seen, 200);
  const json dr = outputDrift(c);
  std::printf(
      "[ figures  ] camera bumped 0.3 deg: re-registered from %d tiles (fit %.3f px); "
      "against the true camera %.3f camera px at worst; now %.3f px; projector "
      "unchanged\n",
      (*corrected)["tiles"].get<int>(), (*corrected)["pose_fit_px"].get<double>(), worst,
      dr.value("misregistration_px", -1.0));
  // A camera pixel covers about 2.5 projector pixels here: 0.2 camera px keeps the
  // registration it measures within the 0.5 projector px bound.
  EXPECT_LE(worst, 0.2);

  // Then the projector bumped (at 16 s): both cameras see it, so it is the projector's
  // pose that is corrected.
  const std::optional<json> pose =
      awaitCorrection(watcher, "corrected-pose", "corrected-camera", registered);
  ASSERT_TRUE(pose) << outputDrift(c).dump() << d.log();
  EXPECT_TRUE(registered) << outputDrift(c).dump();
  const double rig_px = rigAgainstTruth(dir, scene->at(at(17.0)).projectors.at(0).model);
  std::printf(
      "[ figures  ] then the projector bumped 0.5 deg, seen by both cameras: its pose "
      "corrected, the rig against the true projector %.3f px\n",
      rig_px);
  EXPECT_LE(rig_px, 0.5);
}

// The wall moved 1 cm back (to y = 3.01) while the daemon runs: under "on-drift" the
// coarse Gray pass measures it again (the step that ran: "coarse-scan", measuring the
// surface), under "on-drift-silent" the content does (the "surface" step); the projector
// and cameras left as they are; the plane and where the content lands on it checked
// against the truth. `triangulated_by`: who triangulated it, as the correction's event
// names them.
void expectMovedWallMeasuredAgain(const TempDir& dir, DriftRig& r, bool by_scan,
                                  const std::string& triangulated_by) {
  ASSERT_NO_FATAL_FAILURE(r.start(dir));
  auto [scene, d, c, watcher] = std::tie(r.scene, r.d, r.c, r.watcher);
  auto before = rig::rigFromText(rigText(dir), "rig.json");
  ASSERT_TRUE(before) << before.error().message;
  bool registered = false;
  // A scan films its 34 frames with every camera that checks the output: 68 captures with
  // two cameras, each lit again by the virtual camera.
  const std::optional<json> corrected =
      awaitCorrection(watcher, by_scan ? "corrected-scan" : "corrected-surface", "corrected-pose",
                      registered, by_scan ? 90s : 25s);
  ASSERT_TRUE(corrected) << outputDrift(c).dump() << d.log();
  if (by_scan) {
    std::printf("[ figures  ] the coarse Gray pass: %d frames, %.1f s\n",
                (*corrected)["frames"].get<int>(), (*corrected)["scan_s"].get<double>());
    EXPECT_EQ((*corrected)["step"], "coarse-scan");
    EXPECT_EQ((*corrected)["measured"], "surface");
  } else {
    EXPECT_EQ((*corrected)["step"], "surface");
  }
  EXPECT_EQ((*corrected)["triangulated_by"], triangulated_by);
  EXPECT_TRUE(registered) << outputDrift(c).dump();
  auto after = rig::rigFromText(rigText(dir), "rig.json");
  ASSERT_TRUE(after && after->surface.plane) << rigText(dir);
  EXPECT_EQ(rig::rigToJson(*before)["projectors"], rig::rigToJson(*after)["projectors"]);
  EXPECT_EQ(rig::rigToJson(*before)["cameras"], rig::rigToJson(*after)["cameras"]);
  // The measured wall against the true one (the plane y = 3.01).
  const geom::Plane& plane = *after->surface.plane;
  const double turned = std::acos(std::min(1.0, std::abs(plane.n.dot(Vec3::UnitY())))) * 180 / M_PI;
  const double off_mm = 1e3 * std::abs(plane.signedDistance(Vec3(0.0, 3.01, 1.5)));
  // Where the content lands on the true wall against where the rig puts it, in the
  // projector's pixels there.
  const geom::CameraModel projector = scene->at(at(7.0)).projectors.at(0).model;
  const geom::Plane wall{Vec3(0, -1, 0), 3.01};
  double worst_px = 0;
  for (int y = 0; y < projector.height; y += 60) {
    for (int x = 0; x < projector.width; x += 60) {
      auto ray = projector.backproject({x, y});
      auto next = projector.backproject({x + 1, y});
      auto on_true = geom::intersectPlane(*ray, wall);
      auto next_true = geom::intersectPlane(*next, wall);
      auto on_rig = geom::intersectPlane(*ray, plane);
      ASSERT_TRUE(on_true && next_true && on_rig);
      const double pixel = (next_true->point - on_true->point).norm();
      worst_px = std::max(worst_px, (on_rig->point - on_true->point).norm() / pixel);
    }
  }
  const json dr = outputDrift(c);
  const json& e = *corrected;
  const double offset_mm =
      by_scan ? e["wall_offset_mm"].get<double>() : e["why"]["wall_offset_mm"].get<double>();
  std::printf(
      "[ figures  ] wall moved 1 cm back, measured by the %s, triangulated by %s: %.2f mm off "
      "the rig's wall from %d %s; the wall measured again %.3f mm and %.4f deg from the true "
      "one, the content on it %.3f projector px from where the rig puts it; now %.3f px; "
      "projector and cameras unchanged\n",
      by_scan ? "coarse Gray pass" : "content", triangulated_by.c_str(), offset_mm,
      e["points"].get<int>(), by_scan ? "Gray nodes" : "content points", off_mm, turned, worst_px,
      dr.value("misregistration_px", -1.0));
  EXPECT_LE(off_mm, 1.0);
  EXPECT_LE(turned, 0.1);
  EXPECT_LE(worst_px, 0.5);
  EXPECT_LE(dr.value("misregistration_px", 1e9), 0.5);
}

constexpr const char* kWallMovedBack = "\ntarget = \"wall\"\nmove_m = [0.0, 0.01, 0.0]\n";

// One fixed camera, the wall moved 1 cm back: the content moved along the camera's
// epipolar lines with the projector, so the projector's rays and the camera's meet 1 cm
// behind the rig's wall, and the pose fitted to the content would not turn the projector:
// the wall moved. The coarse Gray pass measures it from the projector and the camera.
TEST(SimDrift, AMovedWallIsMeasuredAgainByTheCoarsePass) {
  TempDir dir;
  DriftRig r(dir, "[[events]]\nt = " + atText(6.0) + kWallMovedBack, false);
  expectMovedWallMeasuredAgain(dir, r, true, "the projector and camera 'cam'");
}

// Two fixed cameras: both see the content drift, and where they both found it their rays
// meet 1 cm behind the rig's wall; the coarse Gray pass measures the wall from the two.
TEST(SimDrift, AMovedWallIsMeasuredAgainByTheCoarsePassFromTwoCameras) {
  TempDir dir;
  DriftRig r(dir, "[[events]]\nt = " + atText(6.0) + kWallMovedBack);
  expectMovedWallMeasuredAgain(dir, r, true, "cameras 'cam' and 'cam2'");
}

// recalibrate = "on-drift-silent" shows no pattern: the wall is measured again from the
// content alone, by the two cameras' rays where they found the same content.
TEST(SimDrift, SilentlyAMovedWallIsMeasuredAgainFromTheContent) {
  TempDir dir;
  DriftRig r(dir, "[[events]]\nt = " + atText(6.0) + kWallMovedBack, true, "", "on-drift-silent");
  expectMovedWallMeasuredAgain(dir, r, false, "two cameras");
}

// The same with one camera: the projector's rays and the camera's through the content.
TEST(SimDrift, SilentlyAMovedWallIsMeasuredAgainFromTheContentWithOneCamera) {
  TempDir dir;
  DriftRig r(dir, "[[events]]\nt = " + atText(6.0) + kWallMovedBack, false, "", "on-drift-silent");
  expectMovedWallMeasuredAgain(dir, r, false, "the projector and camera 'cam'");
}

// The projector's zoom ring turned 5 %: no pose with the rig's intrinsics explains the
// content's shift, so the content's correction fails its check and the projector is
// scanned with the coarse Gray pass (34 frames), not the full scan; the rig then puts
// the content where the true, zoomed projector does.
TEST(SimDrift, AZoomedProjectorIsMeasuredAgainWithACoarseScan) {
  TempDir dir;
  const double zoom_t = at(6.0);
  DriftRig r(dir,
             "[[events]]\nt = " + std::to_string(zoom_t) + "\ntarget = \"proj\"\nzoom = 1.05\n",
             false);
  ASSERT_NO_FATAL_FAILURE(r.start(dir));
  auto [scene, d, c, watcher] = std::tie(r.scene, r.d, r.c, r.watcher);
  std::optional<json> detected, scanning, scanned, registered;
  std::vector<std::string> steps;  // every step that ran or failed
  bool status_scanning = false;
  // The coarse scan: 34 captures, each a ray cast of the virtual camera (about 1 s on two
  // idle cores, more when they are busy).
  const auto deadline = Clock::now() + 150s * kSlowdown;
  while (Clock::now() < deadline && !registered) {
    auto e = watcher.next(500ms);
    if (!e || (*e)["event"] != "drift") continue;
    const std::string state = (*e)["state"];
    if (state == "detected" && !detected) detected = *e;
    if (state == "scanning") {
      scanning = *e;
      // Status says so while the scan runs.
      const json dr = outputDrift(c);
      status_scanning = dr.is_object() && dr.value("state", "") == "scanning";
    }
    if (state == "corrected-scan") scanned = *e;
    if (state == "corrected") registered = *e;
    if (e->contains("step")) steps.push_back((*e)["step"].get<std::string>() + ":" + state);
    EXPECT_NE(state, "failed") << e->dump();
  }
  ASSERT_TRUE(detected && scanning && scanned && registered)
      << testing::PrintToString(steps) << d.log();
  // The content's pose could not explain a zoom, so the coarse pass ran, and only it.
  EXPECT_EQ((*scanning)["step"], "coarse-scan") << scanning->dump();
  EXPECT_NE((*scanning)["why"].get<std::string>().find("projector-pose"), std::string::npos)
      << scanning->dump();
  EXPECT_EQ((*scanning)["frames"], 34) << scanning->dump();
  EXPECT_EQ((*scanned)["step"], "coarse-scan");
  EXPECT_EQ((*registered)["scan"], "coarse-scan") << registered->dump();
  EXPECT_TRUE(status_scanning);
  for (const std::string& s : steps) EXPECT_EQ(s.find("full-scan"), std::string::npos) << s;
  const geom::CameraModel truth = scene->at(zoom_t + at(1.0)).projectors.at(0).model;
  EXPECT_NEAR(truth.K.fx, 1.05 * 2400.0, 1e-9);
  const double rig_px = rigAgainstTruth(dir, truth);
  const Measured m = keystoneAgainstTruth(c, truth);
  const json dr = outputDrift(c);
  auto rig = rig::rigFromText(rigText(dir), "rig.json");
  ASSERT_TRUE(rig) << rig.error().message;
  EXPECT_NE(rig->projectors.at(0).calibrated.method.find("drift correction, coarse-scan"),
            std::string::npos)
      << rig->projectors.at(0).calibrated.method;
  EXPECT_EQ(rig->projectors.at(0).name, "proj");
  std::printf(
      "[ figures  ] projector zoomed 5 %%: detected at %.2f px; %s; coarse scan of %d frames "
      "(route %s) in %.1f s; registered at %.3f px; the rig against the true projector %.3f "
      "px, keystone corner %.3f px, aspect %.4f %%, area %.4f %%; steps %s\n",
      (*detected)["check"]["misregistration_px"].get<double>(),
      (*scanning)["why"].get<std::string>().c_str(), (*scanning)["frames"].get<int>(),
      (*scanning)["route"].get<std::string>().c_str(), (*scanned)["scan_s"].get<double>(),
      (*registered)["check"]["misregistration_px"].get<double>(), rig_px, m.corner_px,
      100 * m.aspect_rel, 100 * m.area_rel, testing::PrintToString(steps).c_str());
  EXPECT_LE(rig_px, 0.5);
  EXPECT_LE(m.corner_px, 0.5);
  EXPECT_LE(m.aspect_rel, 1e-3);
  EXPECT_LE(m.area_rel, 5e-3);
  EXPECT_LE(dr.value("misregistration_px", 1e9), 0.5) << dr.dump();
  // The scan's operation is over and the content is back.
  auto st = c.call({{"cmd", "status"}});
  ASSERT_TRUE(st);
  EXPECT_TRUE((*st)["operations"].empty()) << st->dump();
  EXPECT_EQ((*st)["outputs"]["shown"][0]["source"], "content");
}

}  // namespace
}  // namespace procam::itest
