// The frames that carry the automatic keystone (frame_pacing.hpp): while the gyroscope
// carries a turn, each frame's time on the wall is chosen as it is planned and its
// orientation predicted to then; every frame shown is reported with the time it went
// on the wall (`keystone_shown`, PROTOCOL.md). Runs on the loop thread.
#include <algorithm>
#include <chrono>

#include "core/monotonic_clock.hpp"
#include "daemon.hpp"
#include "json_matrix.hpp"
#include "support/render_abi.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// A frame shown more than this after the time asked for counts as late.
constexpr uint64_t kLateNs = 500'000;

}  // namespace

std::optional<KeystoneRuntime::FrameSolution> Daemon::planKeystoneFrame() {
  KeystoneRuntime& k = keystone_rt_;
  if (!settings_.auto_keystone || !k.estimate) return std::nullopt;
  KeystoneRuntime::FrameSolution f;
  f.planned_ns = monotonicNowNs();
  const bool turning = k.gyro && k.gyro->running() && !k.yaw.normal && k.down && k.projector;
  DeviceEntry* out = turning ? devices_.firstUsable(PROCAM_FAMILY_OUTPUT) : nullptr;
  if (out && plugins::outputPresentsAt(out->device.raw())) {
    // After the frame before it (as asked for, or as shown when that was later), which an
    // output may still hold: on a vblank output, at the vblank after its.
    const uint64_t before = std::max(k.last_present_at_ns, k.last_vblank_ns);
    const uint64_t target = std::max(
        presentTarget(f.planned_ns, k.draw_budget.budget(), k.vblank_period_ns, k.last_vblank_ns),
        before + std::max<uint64_t>(1, k.vblank_period_ns));
    const auto at = k.sensor_clock.sensorSeconds(target);
    const double lead = at ? *at - static_cast<double>(k.gyro_last_ns) * 1e-9 : -1;
    const cv::Size content = currentSourceSize();
    if (at && lead >= 0 && lead <= kMaxPredictionLead && content.width > 0 && content.height > 0) {
      if (auto e = solveKeystone(k.gyro->predicted(lead), content)) {
        k.estimate = *e;
        k.estimate_lead = *at - k.down_time;
        f.present_at_ns = k.last_present_at_ns = target;
        f.predicted_time = *at;
      }
    }
  }
  f.solve = k.solves;
  f.H = k.estimate->H;
  f.content_width = k.estimate->content_width;
  f.content_height = k.estimate->content_height;
  return f;
}

void Daemon::keystoneFrameShown(const KeystoneRuntime::FrameSolution& f, const OutputDrawn& r) {
  KeystoneRuntime& k = keystone_rt_;
  if (!r.shown_ns) return;
  const uint64_t shown = *r.shown_ns;
  k.last_vblank_ns = r.vblank_period_ns ? shown : 0;
  k.vblank_period_ns = r.vblank_period_ns;
  if (r.ready_ns >= f.planned_ns) {
    k.draw_budget.add(static_cast<double>(r.ready_ns - f.planned_ns) * 1e-9);
  }
  const bool late = f.present_at_ns && shown > f.present_at_ns + kLateNs;
  if (f.present_at_ns) {
    ++k.paced_frames;
    if (late) ++k.paced_late;
  }
  const auto at = k.sensor_clock.sensorSeconds(shown);
  json e = {{"output", r.name},
            {"updates", f.solve},
            {"display_time", at ? json(*at) : json(nullptr)},
            {"predicted_display_time", f.predicted_time ? json(*f.predicted_time) : json(nullptr)},
            {"late", late},
            {"homography", matrixRows(f.H)},
            {"content_size", {f.content_width, f.content_height}}};
  broadcast("keystone_shown", e);
}

}  // namespace procam::daemon
