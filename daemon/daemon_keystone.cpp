// Auto keystone (PROTOCOL.md: keystone). Everything here runs on the loop thread; the
// keystone solve and the six-position calibration of the virtual rig run on
// compute_worker_ and post their results back. What the outputs show: daemon_outputs.cpp.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/monotonic_clock.hpp"
#include "core/units.hpp"
#include "daemon.hpp"
#include "geometry/homography.hpp"
#include "json_matrix.hpp"
#include "log.hpp"
#include "output_draw.hpp"
#include "request_args.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

json quadJson(const std::array<Vec2, 4>& q) {
  json a = json::array();
  for (const auto& p : q) a.push_back({p.x(), p.y()});
  return a;
}

// The content's corner pixel centres, top-left first, clockwise on screen.
std::array<Vec2, 4> contentCorners(cv::Size s) {
  return {Vec2(0, 0), Vec2(s.width - 1.0, 0), Vec2(s.width - 1.0, s.height - 1.0),
          Vec2(0, s.height - 1.0)};
}

// What the keystone solve needs of the rig model's projector.
ProjectorModel projectorModel(const rig::RigProjector& p) {
  ProjectorModel m;
  m.K = p.K;
  m.width = p.width;
  m.height = p.height;
  m.source = "rig model (" +
             (p.calibrated.method.empty() ? std::string("rig.json") : p.calibrated.method) + ")";
  return m;
}

}  // namespace

void Daemon::setupAutoKeystone() {
  // Policy turns it on at start; a saved setting may too.
  if (config_.auto_keystone) settings_.auto_keystone = true;
  probeKeystoneInputs();
}

// Finds the tilt sensor, the output, the projector's intrinsics and the sensor's
// mount; again on `auto on` while they are missing (a rig model written by
// calibrate, a sensor plugged in). Geometry comes from the rig model only; the
// mount from the rig's projector entry, else from [keystone] in the configuration.
void Daemon::probeKeystoneInputs() {
  KeystoneRuntime& k = keystone_rt_;
  DeviceEntry* tilt = devices_.firstUsable(PROCAM_FAMILY_TILT);
  DeviceEntry* out = devices_.firstUsable(PROCAM_FAMILY_OUTPUT);
  if (!tilt || !out) {
    k.unavailable = !tilt ? "automatic keystone needs a tilt sensor; none is open"
                          : "automatic keystone needs a projector output; none is open";
    if (settings_.auto_keystone) warn(k.unavailable + "; it stays off");
    settings_.auto_keystone = false;
    return;
  }
  k.tilt_device = tilt->name;
  if (!k.hooked) watchTiltSensor();
  k.hooked = true;
  const rig::RigProjector* proj = rig_.projectorForOutput(out->name);
  if (!proj || !proj->intrinsics_known) {
    k.unavailable = "automatic keystone needs the intrinsics of the projector on output '" +
                    out->name + "': the rig model has none (calibrate writes it)";
    if (settings_.auto_keystone) warn(k.unavailable + "; it stays off");
    settings_.auto_keystone = false;
    return;
  }
  Result<TiltMount> mount = mountFromConfig(config_.keystone);
  if (proj->tilt && (proj->tilt->sensor.empty() || proj->tilt->sensor == tilt->name)) {
    TiltMount m;
    m.sensor_from_projector = proj->tilt->sensor_from_projector;
    m.calibration = proj->tilt->calibration;
    m.calibration_source =
        proj->tilt->calibration_source.empty() ? "rig model" : proj->tilt->calibration_source;
    k.calibration_rms_g = proj->tilt->fit_rms_g;
    mount = m;
  }
  if (!mount) {
    k.unavailable = mount.error().message;
    warn(k.unavailable);
    settings_.auto_keystone = false;
    return;
  }
  useKeystoneInputs(projectorModel(*proj), *mount);
}

void Daemon::useKeystoneInputs(ProjectorModel projector, TiltMount mount) {
  KeystoneRuntime& k = keystone_rt_;
  auto tracker = TiltTracker::create(tiltFilterOptions(config_.keystone), std::move(mount));
  if (!tracker) {
    k.unavailable = tracker.error().message;
    warn("automatic keystone: " + k.unavailable);
    settings_.auto_keystone = false;
    return;
  }
  k.tracker = std::move(*tracker);
  k.projector = std::move(projector);
  k.unavailable.clear();
  probeCameraYaw();
  if (settings_.auto_keystone) {
    if (auto ok = setAutoKeystone(true); !ok) warn(ok.error().message);
  }
}

Result<void> Daemon::setAutoKeystone(bool enable) {
  KeystoneRuntime& k = keystone_rt_;
  if (enable && !k.tracker) probeKeystoneInputs();
  if (enable && !k.tracker) return fail(ErrorCode::kNotFound, k.unavailable);
  settings_.auto_keystone = enable;
  if (!enable || !k.tracker) {
    stopTiltPolling();  // the hold and the gyroscope's turn end with the samples
    k.down.reset();
    k.estimate.reset();
    return {};
  }
  if (k.listening) return {};
  DeviceEntry* tilt = devices_.find(k.tilt_device);
  if (!tilt || !tilt->usable()) {
    return fail(ErrorCode::kNotFound, "tilt sensor '" + k.tilt_device + "' is not open");
  }
  k.tracker->reset();
  // A sensor with a poll fd is read by the device manager when readable; the
  // others by timer. Both arrive through the manager's onReading hook.
  if (tilt->device.pollFd() < 0) {
    const auto period =
        std::chrono::nanoseconds(static_cast<int64_t>(1e9 / config_.keystone.poll_hz));
    auto id = device_manager_->pollEvery(k.tilt_device, period);
    if (!id) return tl::unexpected(id.error());
    k.poll_timer = *id;
  }
  k.listening = true;
  return {};
}

void Daemon::stopTiltPolling() {
  KeystoneRuntime& k = keystone_rt_;
  if (k.poll_timer >= 0) device_manager_->stopPolling(k.poll_timer);
  k.poll_timer = -1;
  k.listening = false;
  if (k.tracker) k.tracker->reset();
  // The samples stop: no hold, no turn carries on into the next ones.
  forgetTiltHold();
  if (k.gyro) k.gyro->stop();
  k.gyro_anchor.reset();
  k.gyro_last_ns = 0;
}

void Daemon::watchTiltSensor() {
  device_manager_->onReading([this](const DeviceEntry& e, const Reading& r) {
    if (e.name != keystone_rt_.tilt_device || !keystone_rt_.listening) return;
    if (const auto* s = std::get_if<TiltReading>(&r)) onTiltSample(*s);
  });
  device_manager_->onDeviceRemoved([this](const DeviceEntry& e) {
    KeystoneRuntime& k = keystone_rt_;
    if (e.name != k.tilt_device || !k.listening) return;
    // Keep the setting and the last solution on the wall; resume when it is back.
    stopTiltPolling();
    warn("automatic keystone paused: tilt sensor '" + e.name + "' is gone");
  });
  device_manager_->onDeviceAdded([this](const DeviceEntry& e) {
    KeystoneRuntime& k = keystone_rt_;
    if (e.name != k.tilt_device || !settings_.auto_keystone || k.listening || !k.tracker) return;
    if (auto ok = setAutoKeystone(true); !ok) warn("automatic keystone: " + ok.error().message);
  });
}

void Daemon::onTiltSample(const TiltReading& reading) {
  KeystoneRuntime& k = keystone_rt_;
  if (!k.tracker) return;
  k.reading_arrival = std::chrono::steady_clock::now();
  const procam_tilt_sample& sample = reading.sample;
  k.sensor_clock.add(monotonicNs(k.reading_arrival), sample.timestamp_ns);
  const Vec3 f(sample.specific_force[0], sample.specific_force[1], sample.specific_force[2]);
  const bool was_still = k.tracker->still();
  const auto down = k.tracker->add(f, sample.timestamp_ns);
  if (down) {
    k.down = *down;
    k.down_time = static_cast<double>(sample.timestamp_ns) * 1e-9;
  }
  // A hold that ended takes its wall normal along; the gyroscope then gives this
  // sample's turn, so that a solve made for this sample's time uses it; a new hold
  // starts the camera's look after that solve. One solve per reading: for a new gravity
  // or a turn the gyroscope carried.
  endTiltHold(was_still);
  const bool turned = reading.rate && onGyroRate(*reading.rate, f, was_still);
  if (down || turned) requestSolve();
  startTiltHold();
}

void Daemon::requestSolve() {
  KeystoneRuntime& k = keystone_rt_;
  if (!settings_.auto_keystone || !k.down || !k.projector) return;
  const cv::Size content = currentSourceSize();
  if (content.width < 1 || content.height < 1) return;
  // While the gyroscope carries a turn, the solution is for the moment its frame reaches
  // the wall: the orientation predicted over the measured reading-to-shown latency (at
  // most kMaxPredictionLead: a hand's turn changes within a longer one).
  std::optional<Mat3> R = keystoneOrientation(*k.down);
  double lead = 0;
  if (R && k.gyro && k.gyro->running() && !k.yaw.normal) {
    lead = std::min(k.latency.median(), kMaxPredictionLead);
    R = k.gyro->predicted(lead);
  }
  // Solved here, on the loop: a solve takes microseconds (bench_keystone; 0.1 ms at most
  // in the daemon on two cores), where queued on the compute worker it waited for the
  // frame being drawn, 12 ms of a turning reading's 22 ms to the wall.
  auto e = solveKeystone(R, content);
  if (!e) return;
  k.estimate = *e;
  k.estimate_yaw = cameraYawSource();
  k.unshown_arrival = k.reading_arrival;
  k.estimate_lead = lead;
  ++k.solves;
  broadcast("keystone", keystoneJson());
  refreshOutputs();
}

std::optional<KeystoneEstimate> Daemon::solveKeystone(const std::optional<Mat3>& R,
                                                      cv::Size content) {
  const KeystoneRuntime& k = keystone_rt_;
  Result<KeystoneEstimate> e = [&]() -> Result<KeystoneEstimate> {
    try {
      return R ? keystone::solveFromOrientation(*k.projector, *R, *k.down, content.width,
                                                content.height)
               : solveFromDown(*k.projector, *k.down, content.width, content.height);
    } catch (const std::exception& ex) {
      warn(std::string("keystone solve failed: ") + ex.what());
      return fail(ErrorCode::kInternal, ex.what());
    }
  }();
  if (!e) {
    logDebug("keystone solve: " + e.error().message);
    return std::nullopt;
  }
  e->sample_time = k.down_time;
  return *e;
}

cv::Size Daemon::currentSourceSize() const {
  auto* self = const_cast<Daemon*>(this);  // device queries do not change the set
  FrameRequest r;
  r.pattern = settings_.pattern;
  r.content = keystone_rt_.content;
  if (DeviceEntry* out = self->devices_.firstUsable(PROCAM_FAMILY_OUTPUT)) {
    if (auto mode = outputMode(out->device.raw())) r.output_size = *mode;
  }
  return sourceSize(r);
}

std::optional<Mat3> Daemon::currentWarp(cv::Size content_size) const {
  const KeystoneRuntime& k = keystone_rt_;
  if (settings_.auto_keystone && k.estimate && k.estimate->content_width == content_size.width &&
      k.estimate->content_height == content_size.height) {
    return k.estimate->H;
  }
  if (auto H = rigKeystoneWarp(content_size)) return H;
  if (settings_.keystone) {
    std::array<Vec2, 4> corners;
    for (int i = 0; i < 4; ++i) {
      corners[i] = Vec2((*settings_.keystone)[i][0], (*settings_.keystone)[i][1]);
    }
    if (auto H = geom::homographyFrom4(contentCorners(content_size), corners)) {
      return Mat3(*H / (*H)(2, 2));
    }
  }
  return std::nullopt;
}

json Daemon::keystoneJson() const {
  const KeystoneRuntime& k = keystone_rt_;
  const bool auto_active = settings_.auto_keystone && k.estimate.has_value();
  const cv::Size content = currentSourceSize();
  const json rig = rigKeystoneJson(content);
  const bool rig_active = !auto_active && settings_.rig_keystone && !rig.contains("unavailable");
  json j = {{"auto", settings_.auto_keystone},
            {"rig", settings_.rig_keystone},
            {"mode", auto_active          ? "auto"
                     : rig_active         ? "rig"
                     : settings_.keystone ? "manual"
                                          : "none"},
            {"corners", nullptr},
            {"homography", nullptr},
            {"output_size", nullptr},
            {"content_size", nullptr}};
  if (!k.unavailable.empty()) j["auto_unavailable"] = k.unavailable;
  if (settings_.auto_keystone) {
    j["latency"] = k.latency.toJson();
    // Frames of a turn presented at a time chosen as they were planned (keystone_frames.cpp).
    j["pacing"] = {{"frames", k.paced_frames},
                   {"late", k.paced_late},
                   {"budget_ms", 1e3 * k.draw_budget.budget()},
                   {"vblank_period_ms", 1e-6 * static_cast<double>(k.vblank_period_ns)}};
  }
  if (rig.contains("unavailable")) {
    j["rig_unavailable"] = rig["unavailable"];
  } else if (rig_active) {
    j["wall"] = rig;
    if (const json display = tiledDisplayJson(); !display.is_null()) j["display"] = display;
  }
  if (settings_.keystone && !auto_active && !rig_active) {
    json c = json::array();
    for (const auto& p : *settings_.keystone) c.push_back({p[0], p[1]});
    j["corners"] = c;
  }
  if (k.estimate) {
    const auto& e = *k.estimate;
    j["estimate"] = {{"pitch_deg", radToDeg(e.angles.pitch)},
                     {"roll_deg", radToDeg(e.angles.roll)},
                     {"yaw_deg", radToDeg(e.angles.yaw)},
                     {"yaw_source", k.estimate_yaw},
                     {"down", {e.down.x(), e.down.y(), e.down.z()}},
                     {"scale", e.scale},
                     {"sample_time", e.sample_time},
                     {"lead_ms", 1e3 * k.estimate_lead},
                     {"display_time", e.sample_time + k.estimate_lead},
                     {"updates", k.solves}};
  }
  if (k.projector) {
    j["projector"] = {
        {"intrinsics",
         {k.projector->K.fx, k.projector->K.fy, k.projector->K.cx, k.projector->K.cy}},
        {"size", {k.projector->width, k.projector->height}},
        {"source", k.projector->source}};
  }
  auto* self = const_cast<Daemon*>(this);
  if (k.tracker) {
    const Vec3& off = k.tracker->mount().calibration.offset;
    j["tilt"] = {{"device", k.tilt_device},
                 {"still", k.tracker->still()},
                 {"accepted", nullptr},
                 {"rejected", nullptr},
                 {"rejected_by", nullptr},
                 {"calibration",
                  {{"source", k.tracker->mount().calibration_source},
                   {"offset_g", {off.x(), off.y(), off.z()}}}}};
    if (k.calibration_rms_g >= 0) j["tilt"]["calibration"]["rms_g"] = k.calibration_rms_g;
    j["tilt"]["yaw"] = cameraYawJson();
    j["tilt"]["gyro"] = gyroJson();
    // The driver's sample gate counts (procam_tilt_ops::get_counts), when it has them.
    const DeviceEntry* tilt = self->devices_.find(k.tilt_device);
    if (auto c = tilt && tilt->usable() ? plugins::tiltCounts(tilt->device.raw()) : std::nullopt) {
      j["tilt"]["accepted"] = c->accepted;
      j["tilt"]["rejected"] = plugins::rejectedSamples(*c);
      j["tilt"]["rejected_by"] = {{"not_finite", c->not_finite},
                                  {"out_of_range", c->out_of_range},
                                  {"stuck", c->stuck},
                                  {"bad_norm", c->bad_norm}};
    }
  }
  if (DeviceEntry* out = self->devices_.firstUsable(PROCAM_FAMILY_OUTPUT)) {
    if (auto mode = outputMode(out->device.raw())) j["output_size"] = {mode->width, mode->height};
  }
  if (content.width > 0 && content.height > 0) {
    j["content_size"] = {content.width, content.height};
    if (auto H = currentWarp(content)) {
      j["homography"] = matrixRows(*H);
      if (auto_active || rig_active) {
        std::array<Vec2, 4> c = contentCorners(content);
        for (auto& p : c) p = (*H * p.homogeneous()).hnormalized();
        j["corners"] = quadJson(c);
      }
    }
  }
  return j;
}

void Daemon::cmdKeystone(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "corners", "homography", "enable");
  const std::string action = args.string("action").value_or("get");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  const json* corners = args.get("corners");
  const json* homography = args.get("homography");
  if (action == "get") {
    if (corners || homography || args.get("enable")) {
      return errorTo(client, req, code::kBadArgument, "keystone get takes no arguments");
    }
  } else if (action == "set") {
    if (!corners == !homography) {
      return errorTo(client, req, code::kBadArgument,
                     "keystone set needs \"corners\": 4 [x, y] pairs (or null to clear), or "
                     "\"homography\": 3 rows of 3 numbers");
    }
    Quad q{};
    if (homography) {
      // Stored as the corners it puts the content's corner pixels at.
      Mat3 H;
      bool ok = homography->is_array() && homography->size() == 3;
      for (size_t r = 0; ok && r < 3; ++r) {
        const json& row = (*homography)[r];
        ok = row.is_array() && row.size() == 3;
        for (size_t c = 0; ok && c < 3; ++c) {
          ok = row[c].is_number();
          if (ok) H(r, c) = row[c].get<double>();
        }
      }
      if (!ok || !H.allFinite() || std::abs(H.determinant()) < 1e-12) {
        return errorTo(client, req, code::kBadArgument,
                       "\"homography\" must be 3 rows of 3 finite numbers, not singular");
      }
      const auto src = contentCorners(currentSourceSize());
      for (int i = 0; i < 4; ++i) {
        const Vec3 p = H * src[i].homogeneous();
        if (!(p.z() > 0)) {
          return errorTo(client, req, code::kBadArgument,
                         "\"homography\" sends a content corner to or behind infinity");
        }
        q[i] = {p.x() / p.z(), p.y() / p.z()};
      }
    } else if (!corners->is_null()) {
      if (!corners->is_array() || corners->size() != 4) {
        return errorTo(client, req, code::kBadArgument, "\"corners\" must be 4 [x, y] pairs");
      }
      for (size_t i = 0; i < 4; ++i) {
        const json& p = (*corners)[i];
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
          return errorTo(client, req, code::kBadArgument, "\"corners\" must be 4 [x, y] pairs");
        }
        q[i] = {p[0].get<double>(), p[1].get<double>()};
      }
    }
    if (homography || !corners->is_null()) {
      if (auto ok = validateQuad(q); !ok) {
        return errorTo(client, req, code::kBadArgument, ok.error().message);
      }
      settings_.keystone = q;
    } else {
      settings_.keystone.reset();
    }
    // A manual correction replaces the automatic one and the rig's.
    if (settings_.auto_keystone) (void)setAutoKeystone(false);
    settings_.rig_keystone = false;
    broadcast("keystone", keystoneJson());
    refreshOutputs();
  } else if (action == "auto") {
    auto enable = args.boolean("enable");
    if (!args.ok() || !enable) {
      return errorTo(client, req, code::kBadArgument, "keystone auto needs \"enable\": true|false");
    }
    if (auto ok = setAutoKeystone(*enable); !ok) {
      return errorTo(client, req, code::kUnavailable, ok.error().message);
    }
    if (*enable) settings_.rig_keystone = false;
    broadcast("keystone", keystoneJson());
    refreshOutputs();
  } else if (action == "rig") {
    auto enable = args.boolean("enable");
    if (!args.ok() || !enable || corners || homography) {
      return errorTo(client, req, code::kBadArgument, "keystone rig needs \"enable\": true|false");
    }
    if (auto ok = setRigKeystone(*enable); !ok) {
      return errorTo(client, req, code::kUnavailable, ok.error().message);
    }
    broadcast("keystone", keystoneJson());
    refreshOutputs();
  } else if (action.starts_with("accel-")) {
    if (corners || homography || args.get("enable")) {
      return errorTo(client, req, code::kBadArgument, "keystone " + action + " takes no arguments");
    }
    return accelCalibrationStep(client, req, action);
  } else {
    return errorTo(client, req, code::kBadArgument,
                   "unknown keystone action '" + action +
                       "' (get, set, auto, rig, accel-sample, accel-solve, accel-reset)");
  }
  replyTo(client, req, "KEYSTONE", keystoneJson());
}

// The six-position accelerometer calibration of a real rig, one still hold at
// a time (PROTOCOL.md, "Auto keystone").
void Daemon::accelCalibrationStep(ClientId client, const proto::Request& req,
                                  const std::string& action) {
  KeystoneRuntime& k = keystone_rt_;
  json cal = json::object();
  if (action == "accel-reset") {
    k.accel_holds.clear();
  } else if (action == "accel-sample") {
    if (!k.tracker || !k.listening) {
      return errorTo(client, req, code::kUnavailable,
                     "accel-sample reads the tilt sensor of auto keystone: turn it on first");
    }
    const auto mean = k.tracker->stillMean();
    const long needed = static_cast<long>(std::ceil(config_.keystone.poll_hz));
    if (!mean || mean->second < needed) {
      return errorTo(client, req, code::kUnavailable,
                     "hold the projector still for a second, then sample again");
    }
    auto pose = k.accel_holds.add(mean->first);
    if (!pose) return errorTo(client, req, code::kBadArgument, pose.error().message);
    cal["pose"] = *pose;
    cal["samples"] = mean->second;
    cal["mean_g"] = {mean->first.x(), mean->first.y(), mean->first.z()};
  } else if (action == "accel-solve") {
    auto fit = k.accel_holds.solve();
    if (!fit) return errorTo(client, req, code::kBadArgument, fit.error().message);
    if (!k.tracker) return errorTo(client, req, code::kUnavailable, k.unavailable);
    k.tracker->setCalibration(fit->calibration, "six-position calibration (keystone accel-solve)");
    k.calibration_rms_g = fit->rms;
    k.accel_holds.clear();
    const Vec3& o = fit->calibration.offset;
    const Vec3& g = fit->calibration.scale;
    cal["offset_g"] = {o.x(), o.y(), o.z()};
    cal["scale"] = {g.x(), g.y(), g.z()};
    cal["rms_g"] = fit->rms;
    std::ostringstream toml;
    toml.precision(9);
    toml << "[keystone]\naccel_offset_g = [" << o.x() << ", " << o.y() << ", " << o.z()
         << "]\naccel_scale = [" << g.x() << ", " << g.y() << ", " << g.z() << "]\n";
    cal["config"] = toml.str();  // to keep it: procamd.toml
  } else {
    return errorTo(
        client, req, code::kBadArgument,
        "unknown keystone action '" + action + "' (accel-sample, accel-solve, accel-reset)");
  }
  cal["filled"] = k.accel_holds.filled();
  cal["missing"] = k.accel_holds.missing();
  json body = keystoneJson();
  body["accel_calibration"] = cal;
  replyTo(client, req, "KEYSTONE", body);
}

void Daemon::onRigChanged() {
  loadRigSurfaces();
  repaintObject("the rig model changed");
  // Auto keystone keeps its tilt state and takes the new intrinsics; when it had
  // none, `keystone auto on` reads the rig again.
  KeystoneRuntime& k = keystone_rt_;
  if (settings_.rig_keystone) broadcast("keystone", keystoneJson());  // a new plane mapping
  if (!k.projector) return;
  const DeviceEntry* out = devices_.firstUsable(PROCAM_FAMILY_OUTPUT);
  const rig::RigProjector* p = out ? rig_.projectorForOutput(out->name) : nullptr;
  if (!p || !p->intrinsics_known) return;
  k.projector = projectorModel(*p);
  probeCameraYaw();  // the camera's pose relative to the projector may be new
}

}  // namespace procam::daemon
