// The yaw of the handheld projector from the camera mounted on it, in the running daemon
// ([Raskar02] §6.2.2): at each still hold the output shows a dot grid, the camera's
// frames give the wall's plane in the projector frame, fused with gravity. Judged against
// the projector's TRUE rotation, yaw included, at the tilt sample each solution was made
// from (procamd's keystone accuracy bounds: corner <= 0.5 px, aspect within 0.1 %, area
// within 0.5 % of the largest upright rectangle). While the projector turns, the
// gyroscope in the tilt sensor's package carries the orientation, and each frame is
// judged at the time it went on the wall. The rig model (the
// projector's intrinsics, the camera's pose beside the lens, the accelerometer's mount
// and calibration) is the scene's truth, handed over explicitly.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "daemon_harness.hpp"
#include "keystone_truth.hpp"
#include "sim/scene.hpp"
#include "sim/scene_library.hpp"
#include "truth_rig_file.hpp"

namespace procam::itest {
namespace {

// The holds of the `handheld_tour` scene that combine the largest yaw, pitch and roll the
// handheld projector is specified for: each 10 s long from its start (a 1 s turn before).
struct Hold {
  double start;
  double yaw_deg;
};
constexpr Hold kHolds[] = {{11.0, 30.0}, {22.0, -30.0}, {33.0, -30.0}, {44.0, 30.0}};
constexpr double kHoldLength = 10.0;

TEST(SimCameraYaw, TheCameraOnTheProjectorGivesTheYawOfEachHold) {
  TempDir dir;
  auto scene = sim::resolveScene("handheld_tour");
  ASSERT_TRUE(scene) << scene.error().message;
  DaemonProcess d(dir, simWithTruth(dir, "handheld_tour"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection watcher(d.socketPath()), c(d.socketPath());
  ASSERT_TRUE(watcher.call({{"cmd", "watch"}}));
  auto on = c.call({{"cmd", "keystone"}, {"action", "auto"}, {"enable", true}});
  ASSERT_TRUE(on);
  ASSERT_EQ((*on)["class"], "KEYSTONE") << on->dump();
  ASSERT_EQ((*on)["tilt"]["yaw"]["camera"], "cam") << on->dump();
  // A white frame: every solution changes what the wall shows.
  ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "white"}}))["shown"], true);

  // Per hold the last solution made from this hold's yaw; while the projector turns,
  // every solution the gyroscope carried.
  constexpr std::size_t kN = std::size(kHolds);
  std::array<std::optional<json>, kN> last;
  // While it turns, every frame shown with a solution the gyroscope carried, judged at
  // the time it went on the wall; of those, the frames the output presented at the time
  // the daemon asked for (drawn within their budget).
  std::vector<double> turning_px, on_time_px;
  // Every solution the gyroscope carried, at the time it was solved for (the sample's
  // time plus the lead the daemon predicted over).
  std::vector<double> solved_px;
  std::size_t paced = 0;                   // frames presented at a time the daemon chose
  std::map<long, std::string> yaw_source;  // solution number -> where its yaw came from
  const double end = kHolds[kN - 1].start + kHoldLength;
  const auto deadline = std::chrono::steady_clock::now() + 90s;
  bool done = false;
  while (std::chrono::steady_clock::now() < deadline && !done) {
    auto e = watcher.next(2s);
    if (!e) continue;
    if ((*e)["event"] == "keystone_shown" && (*e)["display_time"].is_number()) {
      const auto source = yaw_source.find((*e)["updates"].get<long>());
      if (source == yaw_source.end() || !source->second.starts_with("gyroscope")) continue;
      const double px = handheldShownAgainstTruth(*scene, *e).corner_px;
      turning_px.push_back(px);
      if ((*e)["predicted_display_time"].is_number()) ++paced;
      if (!(*e)["late"].get<bool>()) on_time_px.push_back(px);
      continue;
    }
    if ((*e)["event"] != "keystone" || (*e)["mode"] != "auto") continue;
    const double t = (*e)["estimate"]["sample_time"].get<double>();
    done = t > end;
    const std::string source = (*e)["estimate"]["yaw_source"].get<std::string>();
    yaw_source[(*e)["estimate"]["updates"].get<long>()] = source;
    if (source.starts_with("gyroscope")) {
      solved_px.push_back(handheldEventAgainstTruth(*scene, *e).corner_px);
    }
    for (std::size_t h = 0; h < kN; ++h) {
      if (t < kHolds[h].start || t > kHolds[h].start + kHoldLength) continue;
      if (source == "camera, this still hold") last[h] = *e;
    }
  }
  for (std::size_t h = 0; h < kN; ++h) {
    ASSERT_TRUE(last[h]) << "hold " << h << "\n" << d.log();
    const Measured m = handheldEventAgainstTruth(*scene, *last[h]);
    const json& yaw = (*last[h])["tilt"]["yaw"]["last"];
    std::printf(
        "hold at %.0f s: at t = %.2f s yaw %.3f deg (wall tilt %.3f deg, %d of %d dots, %.3f px "
        "RMS, %.2f s): corner %.3f px, aspect %.4f %%, area %.4f %%\n",
        kHolds[h].start, (*last[h])["estimate"]["sample_time"].get<double>(),
        yaw["yaw_deg"].get<double>(), yaw["wall_tilt_deg"].get<double>(),
        yaw["dots"]["used"].get<int>(), yaw["dots"]["shown"].get<int>(),
        yaw["rms_px"].get<double>(), yaw["seconds"].get<double>(), m.corner_px, 100 * m.aspect_rel,
        100 * m.area_rel);
    EXPECT_LE(m.corner_px, 0.5) << last[h]->dump();
    EXPECT_LE(m.aspect_rel, 1e-3);
    EXPECT_LE(m.area_rel, 5e-3);
    // A yaw 0.1 degree off moves the corners of this 1400 px lens by about a pixel: the
    // corner bound above is the strict check, this one names the angle.
    EXPECT_NEAR((*last[h])["estimate"]["yaw_deg"].get<double>(), kHolds[h].yaw_deg, 0.1);
  }
  // While the projector turns (1 s between the holds' poses, minimum-jerk as a hand
  // turns), the gyroscope carries the orientation; each frame is asked to go on the wall
  // at a time chosen as it is planned, and the turn predicted to it. Judged against the
  // true pose when each frame went on the wall (procamd's bounds while moving: median
  // 1 px, max 3 px). The turns into the four holds above and the one after them: 5 s.
  // Enough to judge: ten a second of the 5 s (a daemon slowed by a sanitizer coalesces
  // more readings into each frame).
  ASSERT_GE(turning_px.size(), 50u);
  ASSERT_GE(solved_px.size(), 50u);
  std::sort(turning_px.begin(), turning_px.end());
  std::sort(on_time_px.begin(), on_time_px.end());
  std::sort(solved_px.begin(), solved_px.end());
  const double median = turning_px[turning_px.size() / 2];
  std::printf(
      "turning: %zu frames shown with solutions the gyroscope carried (%zu at a time the daemon "
      "chose), corner median %.3f px, 95 %% %.3f px, max %.3f px; the %zu shown on time: max "
      "%.3f px; the %zu solutions at the time solved for: median %.3f px, max %.3f px\n",
      turning_px.size(), paced, median, turning_px[turning_px.size() * 95 / 100], turning_px.back(),
      on_time_px.size(), on_time_px.empty() ? -1.0 : on_time_px.back(), solved_px.size(),
      solved_px[solved_px.size() / 2], solved_px.back());
  if (kSlowdown != 1) {
    // Under the sanitizers a frame takes longer to draw than a turn can be predicted over
    // (50 ms): what is shown is late by construction. The prediction itself is judged at
    // the time each solution was made for.
    EXPECT_LE(solved_px[solved_px.size() / 2], 1.0);
    EXPECT_LE(solved_px.back(), 3.0);
  } else {
    EXPECT_LE(median, 1.0);
    // A frame drawn over its budget goes on late, and the turn moved on meanwhile: the
    // bound is on the frames the output presented when asked. Late ones are a few in a
    // hundred on two shared cores (CPU draws that stall), and are counted.
    ASSERT_FALSE(on_time_px.empty());
    EXPECT_LE(on_time_px.back(), 3.0);
    EXPECT_GE(on_time_px.size(), turning_px.size() * 8 / 10)
        << on_time_px.size() << " of " << turning_px.size();
    // Presented at a chosen time once the sensor's clock is known (the first reading).
    EXPECT_GE(paced, turning_px.size() * 9 / 10) << paced << " of " << turning_px.size();
  }
  // A hold is measured once (six holds; the daemon may start inside the first), none
  // failed, and nothing is measuring any more.
  auto status = c.call({{"cmd", "keystone"}});
  ASSERT_TRUE(status);
  const json& yaw = (*status)["tilt"]["yaw"];
  EXPECT_EQ(yaw["failures"], 0) << yaw.dump();
  EXPECT_GE(yaw["measurements"].get<int>(), 4);
  EXPECT_LE(yaw["measurements"].get<int>(), 6) << yaw.dump();
  // The gyroscope's bias, learnt while held still: the scene's (0.8, -0.6, 0.4) deg/s
  // on the chip's axes (projector right, forward, up: the mount's rows), plus its walk
  // (0.0005 deg/s/sqrt(s): 0.007 deg/s in norm after 55 s, one sigma).
  const json& gyro = (*status)["tilt"]["gyro"];
  ASSERT_TRUE(gyro.is_object()) << status->dump();
  const Vec3 bias(gyro["bias_dps"][0].get<double>(), gyro["bias_dps"][1].get<double>(),
                  gyro["bias_dps"][2].get<double>());
  EXPECT_LT((bias - Vec3(0.8, -0.4, -0.6)).norm(), 0.02) << gyro.dump();
  // The virtual sensor buffers its samples as an IIO device does: a daemon that falls
  // behind under load still integrates every one.
  EXPECT_EQ(gyro["gaps"], 0) << gyro.dump();
  // Every solution reaches the output, and the daemon says how long after its reading:
  // frames that show solutions, at least ten a second over the 5 s of turning as the
  // solutions judged above (solutions that come faster than frames share one frame).
  const json& latency = (*status)["latency"];
  ASSERT_TRUE(latency.is_object()) << status->dump();
  EXPECT_GE(latency["frames"].get<int>(), 50);
  EXPECT_GT(latency["median_ms"].get<double>(), 0.0);
  EXPECT_LE(latency["median_ms"].get<double>(), latency["max_ms"].get<double>());
  std::printf("tilt reading to shown: median %.1f ms, 95 %% %.1f ms, max %.1f ms\n",
              latency["median_ms"].get<double>(), latency["p95_ms"].get<double>(),
              latency["max_ms"].get<double>());
  // Typically within one 60 Hz frame of its reading (the prediction's lead covers what
  // it takes); the tail is printed above. A bound on time: not asserted under the
  // sanitizers, which slow the daemon's drawing by more than their factor on captures.
  if (kSlowdown == 1) {
    EXPECT_LE(latency["median_ms"].get<double>(), 1000.0 / 60.0) << latency.dump();
  }
}

}  // namespace
}  // namespace procam::itest
