// procam-demo: the daemon on the virtual rig. Starts `procamd --sim SCENE` in a
// temporary runtime and state directory, drives it with procamctl (status,
// devices, keystone), follows the frames shown with `procamctl watch` while the
// simulated projector moves along the scene's trajectory, and prints for every frame
// its error against the rig's ground truth at the time it went on the wall; then stops
// the daemon.
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/guarded_main.hpp"
#include "core/units.hpp"
#include "demo/child_process.hpp"
#include "keystone/display_error.hpp"
#include "keystone/keystone_solver.hpp"
#include "keystone/orientation.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"

namespace {

using nlohmann::json;
using procam::Mat3;
using procam::radToDeg;
using procam::Vec2;
namespace demo = procam::demo;
namespace keystone = procam::keystone;
namespace sim = procam::sim;

struct Options {
  std::string scene = "handheld_tour";
  double seconds = 0;  // 0: the trajectory's length plus 4 s of hold
  std::string procamd = PROCAMD_BIN;
  std::string procamctl = PROCAMCTL_BIN;
};

void usage() {
  std::puts(
      "usage: procam-demo [--scene NAME|FILE] [--seconds S] [--procamd PATH] [--procamctl PATH]\n"
      "Runs procamd on the virtual rig (default scene: handheld_tour, auto keystone on)\n"
      "in a temporary directory, drives it with procamctl and prints every keystone\n"
      "update with its error against the rig's ground truth. The scene's wall must be the\n"
      "world frame's plane facing -Y (as in handheld and handheld_tour).");
}

bool parseArgs(int argc, char** argv, Options& out) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") {
      usage();
      std::exit(0);
    }
    if (i + 1 >= argc) return false;
    const std::string v = argv[++i];
    if (a == "--scene") {
      out.scene = v;
    } else if (a == "--seconds") {
      out.seconds = std::atof(v.c_str());
      if (!(out.seconds > 0 && out.seconds < 600)) return false;
    } else if (a == "--procamd") {
      out.procamd = v;
    } else if (a == "--procamctl") {
      out.procamctl = v;
    } else {
      return false;
    }
  }
  return true;
}

Mat3 matrixOf(const json& rows) {
  Mat3 H;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) H(r, c) = rows[r][c].get<double>();
  }
  return H;
}

struct Errors {
  double corner_px = 0, aspect_pct = 0, area_pct = 0;
};

// The shown image's corners judged with orientation R (wall frame -> projector),
// against the largest upright rectangle keystone::solveKeystone finds for R.
Errors errorsAt(const sim::ProjectorSpec& p, const Mat3& R, const Mat3& H, int cw, int ch) {
  keystone::KeystoneProblem problem;
  problem.K = p.K;
  problem.width = p.width;
  problem.height = p.height;
  problem.R = R;
  problem.content_width = cw;
  problem.content_height = ch;
  auto best = keystone::solveKeystone(problem);
  const std::array<Vec2, 4> edges = {Vec2(-0.5, -0.5), Vec2(cw - 0.5, -0.5),
                                     Vec2(cw - 0.5, ch - 0.5), Vec2(-0.5, ch - 0.5)};
  std::array<Vec2, 4> shown;
  for (int i = 0; i < 4; ++i) shown[i] = (H * edges[i].homogeneous()).hnormalized();
  const auto e = keystone::displayError(p.K, R, shown);
  Errors out;
  out.corner_px = e.max_corner_px;
  out.aspect_pct = 100 * std::abs(e.aspect / (double(cw) / ch) - 1);
  out.area_pct = best ? 100 * std::abs(e.area / best->rect.area() - 1) : NAN;
  return out;
}

void section(const char* title) {
  std::printf("\n== %s\n", title);
  std::fflush(stdout);
}

}  // namespace

static int run(int argc, char** argv) {
  Options opt;
  if (!parseArgs(argc, argv, opt)) {
    usage();
    return 2;
  }
  auto scene_or = sim::resolveScene(opt.scene);
  if (!scene_or) {
    std::fprintf(stderr, "procam-demo: %s\n", scene_or.error().message.c_str());
    return 1;
  }
  const sim::Scene& scene = *scene_or;
  if (scene.projectors().empty() || scene.tiltSensors().empty()) {
    std::fprintf(stderr, "procam-demo: scene '%s' needs a projector with a tilt sensor\n",
                 scene.name().c_str());
    return 1;
  }
  const sim::ProjectorSpec& pspec = scene.projectors().front();
  double trajectory = 0;
  for (const auto& tr : scene.trajectories()) trajectory = std::max(trajectory, tr.duration());
  const double seconds = opt.seconds > 0 ? opt.seconds : trajectory + 4.0;

  char tmpl[] = "/tmp/procam-demo.XXXXXX";
  if (!::mkdtemp(tmpl)) {
    std::perror("procam-demo: mkdtemp");
    return 1;
  }
  const std::string dir = tmpl;
  const std::string socket = dir + "/run/control.sock";
  const std::string log = dir + "/procamd.log";
  auto ctl = [&](std::vector<std::string> args) {
    args.insert(args.begin(), {opt.procamctl, "--socket", socket});
    return demo::runToEnd(args);
  };

  // procamd learns nothing from the simulator but its devices: the rig model (the
  // projector's intrinsics and the accelerometer's mount and calibration) is handed
  // over explicitly, as a calibrated rig's rig.json would be.
  section("the rig model: the scene's truth, handed to procamd explicitly");
  const std::string rig_file = dir + "/rig.json";
  std::printf("$ procam-sim truth --scene %s --rig-json %s\n", opt.scene.c_str(), rig_file.c_str());
  {
    auto rig = sim::truthRig(scene, 0.0);
    if (!rig) {
      std::fprintf(stderr, "procam-demo: %s\n", rig.error().message.c_str());
      return 1;
    }
    std::ofstream f(rig_file);
    f << procam::rig::rigToJson(*rig).dump(2) << "\n";
    if (!f.flush()) {
      std::fprintf(stderr, "procam-demo: cannot write %s\n", rig_file.c_str());
      return 1;
    }
    for (const auto& p : rig->projectors) {
      if (p.tilt) {
        std::printf("projector '%s': K fx=%.1f fy=%.1f; tilt sensor '%s': %s, fit RMS %.3f mg\n",
                    p.name.c_str(), p.K.fx, p.K.fy, p.tilt->sensor.c_str(),
                    p.tilt->calibration_source.c_str(), p.tilt->fit_rms_g * 1e3);
      }
    }
  }

  section("start procamd on the virtual rig");
  std::printf("$ procamd --sim %s --rig %s --runtime-dir %s/run --state-dir %s/state  (log: %s)\n",
              opt.scene.c_str(), rig_file.c_str(), dir.c_str(), dir.c_str(), log.c_str());
  auto daemon = demo::Child::start({opt.procamd, "--sim", opt.scene, "--rig", rig_file,
                                    "--runtime-dir", dir + "/run", "--state-dir", dir + "/state"},
                                   log, false);
  if (!daemon) {
    std::fprintf(stderr, "procam-demo: cannot start %s\n", opt.procamd.c_str());
    return 1;
  }
  bool up = false;
  for (int i = 0; i < 100 && !up; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    up = std::filesystem::exists(socket) && ctl({"version"}).status == 0;
  }
  if (!up) {
    std::fprintf(stderr, "procam-demo: procamd did not come up; see %s\n", log.c_str());
    return 1;
  }
  section("procamctl status");
  std::fputs(ctl({"status"}).out.c_str(), stdout);
  section("procamctl devices");
  std::fputs(ctl({"devices"}).out.c_str(), stdout);
  section("procamctl keystone auto on");
  const auto on = ctl({"keystone", "auto", "on"});
  std::fputs(on.out.c_str(), stdout);
  // A white frame on the wall: every keystone update is drawn and shown.
  section("procamctl pattern white");
  std::fputs(ctl({"pattern", "white"}).out.c_str(), stdout);

  section("frames shown while the projector moves (procamctl --json watch)");
  std::printf(
      "Each frame shown judged with the projector's TRUE orientation (yaw, pitch and roll)\n"
      "at the time it went on the wall (procamd's `keystone_shown`: the output's present\n"
      "time; while the projector turns, procamd asks the output to present each frame at a\n"
      "time it chose and predicts the turn to it): corner px in the framebuffer, aspect and\n"
      "area against the largest upright\n"
      "rectangle. Gravity gives pitch and roll; the camera on the projector gives the yaw at\n"
      "each still hold ([Raskar02] §6.2.2), the gyroscope carries it while the projector\n"
      "turns.\n\n");
  std::printf("%7s %6s | %6s %6s %6s | %6s %6s %6s %-7s | %8s %8s %7s\n", "t [s]", "still", "pitch",
              "roll", "yaw", "est p", "est r", "est y", "yaw by", "corner", "aspect%", "area%");
  auto watch = demo::Child::start({opt.procamctl, "--socket", socket, "--json", "watch"});
  if (!watch) return 1;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int updates = 0, hidden = 0;
  double last_printed = -1;
  std::vector<double> moving_px;   // corner errors while the projector moves
  std::vector<double> on_time_px;  // of those, frames shown at the time procamd asked for
  double worst_moving = -1, worst_moving_t = 0;
  std::string worst_moving_by;
  // The last update of each still hold whose yaw the camera measured in that hold,
  // keyed by the measurement's count.
  std::map<long, std::pair<double, Errors>> holds;
  // Each solution as published (`keystone`), by its update count: whether the sensor
  // was still, the estimate and where its yaw came from.
  std::map<long, json> published;
  int late = 0, paced = 0;
  std::vector<double> predicted_off_ms;  // shown - predicted display time, paced frames
  while (std::chrono::steady_clock::now() < end) {
    auto line = watch->readLine(std::chrono::milliseconds(200));
    if (!line) continue;
    const json e = json::parse(*line, nullptr, false);
    if (e.is_discarded()) continue;
    const std::string event = e.value("event", "");
    if (event == "keystone" && e.value("mode", "") == "auto" && e.contains("estimate")) {
      published[e["estimate"].value("updates", 0L)] = e;
      while (published.size() > 256) published.erase(published.begin());
      continue;
    }
    if (event != "keystone_shown" || !e["display_time"].is_number()) continue;
    const auto info = published.find(e.value("updates", 0L));
    if (info == published.end()) continue;
    const json& k = info->second;
    ++updates;
    // Judged when the frame went on the wall, as procamd saw its output present it.
    const double t = e["display_time"].get<double>();
    if (e["predicted_display_time"].is_number()) {
      ++paced;
      if (e.value("late", false)) ++late;
      predicted_off_ms.push_back(1e3 * (t - e["predicted_display_time"].get<double>()));
    }
    const int cw = e["content_size"][0].get<int>(), ch = e["content_size"][1].get<int>();
    const Mat3 H = matrixOf(e["homography"]);
    // The handheld wall is the world plane y = const facing -y: wall frame = world frame.
    const Mat3 R_true = scene.at(t).projector(pspec.name)->model.pose.R;
    const keystone::Angles truth = keystone::anglesFromRotation(R_true);
    const Errors full = errorsAt(pspec, R_true, H, cw, ch);
    const bool still = k["tilt"].value("still", false);
    const json& yaw = k["tilt"]["yaw"];
    const std::string source = k["estimate"].value("yaw_source", "");
    const bool this_hold = source == "camera, this still hold";
    const char* yaw_by = this_hold                         ? "camera"
                         : source.starts_with("gyroscope") ? "gyro"
                         : source.starts_with("kept")      ? "kept"
                                                           : "none";
    // Moving by the scene's truth (the sensor's own `still` also covers the filter's
    // start, before it has seen a still second).
    const Mat3 turn = scene.at(t + 0.005).projector(pspec.name)->model.pose.R *
                      scene.at(t - 0.005).projector(pspec.name)->model.pose.R.transpose();
    const bool moving = Eigen::AngleAxisd(turn).angle() > 1e-9;
    if (moving) {
      if (full.corner_px > worst_moving) {
        worst_moving = full.corner_px;
        worst_moving_t = t;
        worst_moving_by = yaw_by;
      }
      moving_px.push_back(full.corner_px);
      if (!e.value("late", false)) on_time_px.push_back(full.corner_px);
    }
    if (still && this_hold) holds[yaw.value("measurements", 0L)] = {t, full};
    // While moving the daemon updates on every sample: print ten a second.
    if (!still && t - last_printed < 0.1) {
      ++hidden;
      continue;
    }
    last_printed = t;
    std::printf("%7.2f %6s | %6.1f %6.1f %6.1f | %6.2f %6.2f %6.2f %-7s | %8.3f %8.4f %7.4f\n", t,
                still ? "yes" : "no", radToDeg(truth.pitch), radToDeg(truth.roll),
                radToDeg(truth.yaw), k["estimate"]["pitch_deg"].get<double>(),
                k["estimate"]["roll_deg"].get<double>(), k["estimate"].value("yaw_deg", 0.0),
                yaw_by, full.corner_px, full.aspect_pct, full.area_pct);
    std::fflush(stdout);
  }
  watch->stop();
  std::printf("\n%d frame(s) shown in %.1f s (%d not printed).\n", updates, seconds, hidden);
  if (!holds.empty()) {
    Errors worst;
    for (const auto& [n, hold] : holds) {
      worst.corner_px = std::max(worst.corner_px, hold.second.corner_px);
      worst.aspect_pct = std::max(worst.aspect_pct, hold.second.aspect_pct);
      worst.area_pct = std::max(worst.area_pct, hold.second.area_pct);
    }
    std::printf(
        "Held still (%zu holds, the last update of each, yaw from the camera): worst corner "
        "%.3f px, aspect %.4f %%, area %.4f %%\n"
        "  (procamd's keystone accuracy bounds: corner <= 0.5 px, aspect 0.1 %%, area 0.5 %%).\n",
        holds.size(), worst.corner_px, worst.aspect_pct, worst.area_pct);
  } else {
    std::printf("No still hold had its yaw measured by a camera (see `keystone` below).\n");
  }
  if (!moving_px.empty()) {
    std::sort(moving_px.begin(), moving_px.end());
    std::sort(on_time_px.begin(), on_time_px.end());
    const auto at = [](const std::vector<double>& v, double q) {
      return v.empty() ? 0.0 : v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
    };
    std::printf(
        "While the projector moves (%zu frames): corner error median %.2f px, 95 %% %.2f px,\n"
        "  max %.2f px (at t = %.2f s, yaw by %s); the %zu frames shown at the time procamd\n"
        "  asked for: median %.2f px, max %.2f px. The gyroscope carries the orientation where\n"
        "  the tilt sensor has one; otherwise the tilt low-pass lags the motion and the yaw is\n"
        "  the last hold's until the next.\n",
        moving_px.size(), at(moving_px, 0.5), at(moving_px, 0.95), moving_px.back(), worst_moving_t,
        worst_moving_by.c_str(), on_time_px.size(), at(on_time_px, 0.5),
        on_time_px.empty() ? 0.0 : on_time_px.back());
  }
  if (!predicted_off_ms.empty()) {
    std::sort(predicted_off_ms.begin(), predicted_off_ms.end());
    std::printf(
        "Frames presented at a time procamd chose (%d): %d late by more than 0.5 ms (drawn\n"
        "  over their budget); shown minus asked-for time median %.3f ms, max %.3f ms.\n",
        paced, late, predicted_off_ms[predicted_off_ms.size() / 2], predicted_off_ms.back());
  }

  section("procamctl keystone");
  std::fputs(ctl({"keystone"}).out.c_str(), stdout);
  section("stop procamd (SIGTERM)");
  const int status = daemon->stop();
  std::printf("procamd exited with status %d\n", status);
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return status == 0 && updates > 0 ? 0 : 1;
}

int main(int argc, char** argv) {
  return procam::guardedMain("procam-demo", [&] { return run(argc, argv); });
}
