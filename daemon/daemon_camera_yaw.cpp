// The yaw of a handheld projector from the camera mounted on it ([Raskar02] §6.2.2: tilt
// sensors give pitch and roll, the rigid camera the azimuth; §6.3 the self-correcting
// projector). At the start of every still hold the tilt sensor reports, the output shows a
// dot grid for [keystone] yaw_frames camera frames (content held back meanwhile, on the
// compute worker that draws the outputs and runs calibrations, so nothing interleaves),
// the wall's plane is fitted in the projector frame and fused with gravity. While the
// projector turns, the gyroscope in the tilt sensor's package (when it has one) carries
// the last still orientation (keystone/gyro_orientation.hpp). Everything here runs on
// the loop thread.
#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "daemon.hpp"
#include "log.hpp"
#include "output_draw.hpp"
#include "protocol.hpp"
#include "wall_sight.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// The wall auto keystone corrects for is vertical; a plane leaning more is not it.
constexpr double kMaxWallTilt = degToRad(5.0);

// A gyroscope turning slower than this (bias removed) is still: about 14 sigma of a
// 0.005 deg/s/sqrt(Hz) gyroscope read at 100 Hz, under a tenth of a pixel per frame.
constexpr double kQuietRate = degToRad(0.5);
// A gap between readings that a sensor at 100 Hz or more never leaves on its own: five
// sample periods at 100 Hz.
constexpr uint64_t kGyroGapNs = 50'000'000;

}  // namespace

void Daemon::probeCameraYaw() {
  // Which camera, how it sits and what it shows; the yaw measured so far is kept (a
  // camera unplugged or a rig model rewritten does not turn the wall).
  KeystoneRuntime::CameraYaw& y = keystone_rt_.yaw;
  stopCameraYaw();
  y.camera.clear();
  y.grid.reset();
  if (!config_.keystone.camera_yaw) {
    y.unavailable = "off ([keystone] camera_yaw = false)";
    return;
  }
  DeviceEntry* out = devices_.firstUsable(PROCAM_FAMILY_OUTPUT);
  const rig::RigProjector* p = out ? rig_.projectorForOutput(out->name) : nullptr;
  if (!p || !p->intrinsics_known || !p->pose_known) {
    y.unavailable = "the rig model has no posed projector for the output";
    return;
  }
  const rig::RigCamera* c = rig_.attachedCamera(p->name);
  if (!c) {
    y.unavailable = "the rig model has no posed camera mounted on projector '" + p->name +
                    "' (rig.json cameras[].attached_to)";
    return;
  }
  DeviceEntry* cam = devices_.find(c->name);
  if (!cam || cam->description.family != PROCAM_FAMILY_CAMERA || !cam->usable()) {
    y.unavailable = "camera '" + c->name + "', mounted on projector '" + p->name + "', is not open";
    return;
  }
  const auto mode = outputMode(out->device.raw());
  if (!mode || mode->width != p->width || mode->height != p->height) {
    y.unavailable = "output '" + out->name + "' does not show the " + std::to_string(p->width) +
                    "x" + std::to_string(p->height) + " framebuffer the rig model calibrated";
    return;
  }
  auto grid = keystone::makeDotGrid(p->width, p->height);
  if (!grid) {
    y.unavailable = grid.error().message;
    return;
  }
  // Camera from projector: both poses were calibrated together, in one world frame.
  geom::CameraModel in_projector = c->model;
  in_projector.pose = c->model.pose.relativeTo(p->pose);
  if (!(in_projector.pose.t.norm() > 1e-3)) {
    y.unavailable = "camera '" + c->name + "' sits within 1 mm of the projector's lens: no " +
                    "baseline to see the wall's direction from";
    return;
  }
  y.in_projector = in_projector;
  y.grid = std::make_shared<const keystone::DotGrid>(std::move(*grid));
  y.camera = c->name;
  y.output = out->name;
  y.unavailable.clear();
}

void Daemon::stopCameraYaw() {
  KeystoneRuntime::CameraYaw& y = keystone_rt_.yaw;
  if (y.stop) y.stop->store(true);
}

// Called after every tilt sample with the tracker's stillness before it.
void Daemon::endTiltHold(bool was_still) {
  KeystoneRuntime& k = keystone_rt_;
  if (was_still && !(k.tracker && k.tracker->still())) forgetTiltHold();
}

void Daemon::forgetTiltHold() {
  // The hold ended: its wall normal no longer holds; its yaw is kept as the best guess.
  KeystoneRuntime::CameraYaw& y = keystone_rt_.yaw;
  y.normal.reset();
  y.tried_this_hold = false;
  stopCameraYaw();
}

void Daemon::startTiltHold() {
  KeystoneRuntime& k = keystone_rt_;
  KeystoneRuntime::CameraYaw& y = k.yaw;
  const bool still = k.tracker && k.tracker->still();
  if (still && !y.tried_this_hold && !y.measuring && settings_.auto_keystone) measureCameraYaw();
}

void Daemon::measureCameraYaw() {
  KeystoneRuntime::CameraYaw& y = keystone_rt_.yaw;
  y.tried_this_hold = true;
  if (!config_.keystone.camera_yaw || calibrating()) return;
  if (y.camera.empty()) probeCameraYaw();  // a camera plugged in, a rig model written
  if (y.camera.empty()) return;
  DeviceEntry* out = devices_.find(y.output);
  DeviceEntry* cam = devices_.find(y.camera);
  if (!out || !out->usable() || !cam || !cam->usable()) {
    y.unavailable = "camera '" + y.camera + "' or output '" + y.output + "' is not open";
    y.camera.clear();
    return;
  }
  WallSightPlan plan;
  plan.output = {out->name, out->device.share()};
  plan.camera = {cam->name, cam->device.share()};
  plan.grid = y.grid;
  const rig::RigProjector* p = rig_.projectorForOutput(out->name);
  if (!p) return;
  plan.projector = p->K;
  plan.camera_in_projector = y.in_projector;
  plan.frames = config_.keystone.yaw_frames;
  uint32_t w = 0, h = 0;
  double refresh = 0;
  const auto& raw = out->device.raw();
  if (raw.ops.output->get_mode(raw.self, &w, &h, &refresh) != PROCAM_OK || !(refresh > 0)) {
    refresh = 60;
  }
  plan.settle_s = std::max(1, config_.calibration.settle_frames) / refresh;
  y.stop = std::make_shared<std::atomic<bool>>(false);
  plan.stop = y.stop;
  y.measuring = true;
  logDebug("camera yaw: the dot grid on '" + y.output + "' for " + std::to_string(plan.frames) +
           " frames of camera '" + y.camera + "'");
  auto finished = [this](tl::expected<WallSight, CalibrationFailure> r,
                         std::shared_ptr<std::atomic<bool>> stop) {
    KeystoneRuntime& k = keystone_rt_;
    KeystoneRuntime::CameraYaw& y = k.yaw;
    y.measuring = false;
    if (!r) {
      if (std::string(r.error().code) != proto::code::kCancelled) {
        ++y.failures;
        y.last = {{"measured", false}, {"why", r.error().message}};
        warn("camera yaw: " + r.error().message + "; the yaw stays as it was");
      }
    } else if (!stop->load() && k.tracker && k.tracker->still() && k.down) {
      const keystone::WallFromDots& wall = r->wall;
      auto fused = keystone::fuseOrientation(*k.down, wall.plane.normal);
      if (!fused || fused->wall_tilt > kMaxWallTilt) {
        // A wall far from vertical by gravity is another surface, or a bad fit: the yaw
        // stays as it was.
        const std::string why =
            !fused ? fused.error().message
                   : "the plane seen leans " + std::to_string(radToDeg(fused->wall_tilt)) +
                         " degrees from vertical (at most " +
                         std::to_string(radToDeg(kMaxWallTilt)) + "): not the wall";
        ++y.failures;
        y.last = {{"measured", false}, {"why", "the wall's normal: " + why}};
        warn("camera yaw: " + why);
      } else {
        y.normal = wall.plane.normal;
        y.yaw = keystone::anglesFromRotation(fused->R).yaw;
        ++y.measurements;
        y.last = {
            {"measured", true},
            {"yaw_deg", radToDeg(*y.yaw)},
            {"wall_tilt_deg", radToDeg(fused->wall_tilt)},
            {"distance_m", wall.plane.distance},
            {"rms_px", wall.plane.rms},
            {"dots", {{"shown", wall.shown}, {"found", wall.detected}, {"used", wall.matched}}},
            {"frames", r->frames},
            {"seconds", r->seconds},
            {"sample_time", k.down_time}};
        requestSolve();
      }
    }
    // The content again. A reading from before the grid ended waited for the
    // measurement: refreshOutputs does not count its latency.
    k.grid_ended = std::chrono::steady_clock::now();
    refreshOutputs();
  };
  compute_worker_->submit(
      [plan, finished] {
        auto r = measureWallSight(plan);
        return [finished, r = std::move(r), stop = plan.stop]() mutable {
          finished(std::move(r), stop);
        };
      },
      [this](const std::string& what) {
        keystone_rt_.yaw.measuring = false;
        warn("camera yaw failed: " + what);
        refreshOutputs();
      });
}

bool Daemon::onGyroRate(const procam_rate_sample& sample, const Vec3& specific_force,
                        bool was_still) {
  KeystoneRuntime& k = keystone_rt_;
  if (!k.tracker || !settings_.auto_keystone) return false;
  const Mat3& M = k.tracker->mount().sensor_from_projector;  // row i: sensor axis i
  const Vec3 w = M.transpose() * Vec3(sample.angular_velocity[0], sample.angular_velocity[1],
                                      sample.angular_velocity[2]);
  if (sample.timestamp_ns <= k.gyro_last_ns) return false;  // not newer: read twice
  if (k.gyro && k.gyro->running() && k.gyro_last_ns > 0 &&
      sample.timestamp_ns - k.gyro_last_ns > kGyroGapNs) {
    ++k.gyro_gaps;
    logDebug("gyroscope: " + std::to_string((sample.timestamp_ns - k.gyro_last_ns) / 1'000'000) +
             " ms between readings while the projector turned");
  }
  k.gyro_last_ns = sample.timestamp_ns;
  ++k.gyro_samples;
  k.gyro_rate = w;
  const bool still = k.tracker->still();
  if (still) k.gyro_bias.addStill(w);
  if (was_still && !still) k.gyro_bias.endHold();
  if (!k.gyro) {
    auto g = keystone::GyroOrientation::create();
    if (!g) return false;
    k.gyro = std::move(*g);
  }
  const Vec3 rate = w - k.gyro_bias.value();
  // Still by both sensors: the orientation of the hold (gravity and the camera) is the
  // anchor the next turn starts from. Until the camera has looked (when one will), the
  // gyroscope keeps carrying the turn's orientation: the accelerometer's first still
  // mean is a few hundred milliseconds long, the turn's end is better known.
  if (still && (!k.gyro_bias.known() || rate.norm() < kQuietRate)) {
    const bool camera_pending =
        !k.yaw.camera.empty() && !k.yaw.normal && (!k.yaw.tried_this_hold || k.yaw.measuring);
    if (k.gyro->running() && camera_pending) {
      const Vec3 f = k.tracker->mount().calibration.apply(specific_force / kStandardGravity);
      k.gyro->update(rate, keystone::downFromSpecificForce(M.transpose(), f), sample.timestamp_ns);
      return false;
    }
    if (k.gyro->running()) {
      // A turn ended: its yaw is a better guess than the last hold's, unless the camera
      // has looked meanwhile.
      if (!k.yaw.normal) k.yaw.yaw = keystone::anglesFromRotation(k.gyro->R()).yaw;
      k.gyro->stop();
    }
    if (k.down) {
      if (auto R = keystoneOrientation(*k.down)) {
        k.gyro_anchor = *R;
      } else if (auto G = keystone::rotationFromDown(*k.down)) {
        k.gyro_anchor = *G;
      }
      k.gyro_anchor_ns = sample.timestamp_ns;
      k.gyro_anchor_rate = rate;
    }
    return false;
  }
  if (!k.gyro->running()) {
    if (!k.gyro_anchor) return false;
    k.gyro->start(*k.gyro_anchor, k.gyro_anchor_ns, k.gyro_anchor_rate);
  }
  if (still) {
    // The gyroscope feels a turn before the accelerometer's filter does: the hold is
    // over, its wall normal no longer holds and a measurement under way stops.
    k.yaw.normal.reset();
    stopCameraYaw();
  }
  const Vec3 f = k.tracker->mount().calibration.apply(specific_force / kStandardGravity);
  const Vec3 down = keystone::downFromSpecificForce(M.transpose(), f);
  const Mat3 before = k.gyro->R();
  k.gyro->update(rate, down, sample.timestamp_ns);
  if (!k.gyro->running()) {
    // The readings stalled mid-turn: go on from this reading's gravity and the yaw
    // carried so far (the pull to gravity then smooths the accelerometer's noise).
    auto tilt = keystone::tiltFromDown(down);
    if (!tilt) return false;
    tilt->yaw = keystone::anglesFromRotation(before).yaw;
    k.gyro->start(keystone::rotationFromAngles(*tilt), sample.timestamp_ns, rate);
  }
  k.down_time = static_cast<double>(sample.timestamp_ns) * 1e-9;
  return true;  // every reading while it turns is solved
}

std::optional<Mat3> Daemon::keystoneOrientation(const Vec3& down) const {
  const KeystoneRuntime& k = keystone_rt_;
  const KeystoneRuntime::CameraYaw& y = k.yaw;
  if (y.normal) {
    if (auto fused = keystone::fuseOrientation(down, *y.normal)) return fused->R;
  }
  if (k.gyro && k.gyro->running()) return k.gyro->R();
  if (y.yaw) {
    if (auto a = keystone::tiltFromDown(down)) {
      a->yaw = *y.yaw;
      return keystone::rotationFromAngles(*a);
    }
  }
  return std::nullopt;
}

std::string Daemon::cameraYawSource() const {
  const KeystoneRuntime& k = keystone_rt_;
  const KeystoneRuntime::CameraYaw& y = k.yaw;
  if (k.gyro && k.gyro->running() && !y.normal) return "gyroscope, since the last still hold";
  return y.normal ? "camera, this still hold"
         : y.yaw  ? "kept from the last still hold"
                  : "none: yaw 0";
}

json Daemon::cameraYawJson() const {
  const KeystoneRuntime::CameraYaw& y = keystone_rt_.yaw;
  json j = {
      {"source", cameraYawSource()}, {"camera", y.camera.empty() ? json(nullptr) : json(y.camera)},
      {"measuring", y.measuring},    {"measurements", y.measurements},
      {"failures", y.failures},      {"last", y.last}};
  if (!y.unavailable.empty()) j["unavailable"] = y.unavailable;
  if (y.yaw) j["yaw_deg"] = radToDeg(*y.yaw);
  return j;
}

json Daemon::gyroJson() const {
  const KeystoneRuntime& k = keystone_rt_;
  if (k.gyro_samples == 0) return nullptr;
  const Vec3 b = k.gyro_bias.value() * (180 / std::numbers::pi);
  const Vec3 w = k.gyro_rate * (180 / std::numbers::pi);
  return {{"samples", k.gyro_samples},
          {"rate_dps", {w.x(), w.y(), w.z()}},
          {"bias_dps", k.gyro_bias.known() ? json{b.x(), b.y(), b.z()} : json(nullptr)},
          {"carrying", k.gyro && k.gyro->running()},
          {"gaps", k.gyro_gaps}};
}

}  // namespace procam::daemon
