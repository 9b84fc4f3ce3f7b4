// Trackers and camera readings in the running daemon (PROTOCOL.md "Trackers"):
// every usable tracker is read at its rate, its latest pose kept raw and in the
// world frame ([Raskar02] §4.1.2 "Tracked Viewer Registration", §4.1.4), cameras with
// a poll fd are counted as their frames arrive, and `tracker register` fits the
// tracker -> world registration (eq. 4.2, §4.2.5) kept in tracker.json.
#include <algorithm>
#include <cmath>

#include "daemon.hpp"
#include "json_matrix.hpp"
#include "log.hpp"
#include "request_args.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

// Trackers whose rate the daemon cannot learn are polled this fast; a reading
// that repeats the last timestamp is not counted, so the measured rate stays
// the tracker's own up to this.
constexpr double kDefaultTrackerPollHz = 120;

StateFile trackerFile(const std::string& state_dir) {
  return StateFile(state_dir, kTrackerFile, [](std::string_view text) -> Result<void> {
    if (auto r = trackerFileFromText(text); !r) return tl::unexpected(r.error());
    return {};
  });
}

// The tracker's sample rate, as its driver reports it (procam_tracker_ops::get_rate).
double trackerPollHz(const DeviceEntry& e) {
  return plugins::trackerRate(e.device.raw()).value_or(kDefaultTrackerPollHz);
}

const char* errorCode(ErrorCode c) {
  switch (c) {
    case ErrorCode::kTooFewPoints:
      return code::kTooFewPoints;
    case ErrorCode::kDegenerate:
      return code::kDegenerate;
    default:
      return code::kBadArgument;
  }
}

double ageSeconds(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

void Daemon::setupTrackers() {
  auto loaded = trackerFile(options_.state_dir).read();
  if (loaded) {
    if (loaded->from_backup) warn(loaded->warning);
    trackers_.registrations = *trackerFileFromText(loaded->contents);  // validated by read()
    logInfo(std::to_string(trackers_.registrations.size()) + " tracker registration(s) restored");
  } else if (loaded.error().code != ErrorCode::kNotFound) {
    warn("tracker registrations not restored: " + loaded.error().message);
  }
  // calibrate captures its cameras on a worker: the manager keeps off them meanwhile.
  // So does the drift check with the camera it drives.
  device_manager_->setReadGate([this](const std::string& name) {
    const auto& used = calibration_.devices;
    if (drift_rt_.checking && name == drift_rt_.camera_in_use) return false;
    return calibration_.op.empty() || std::find(used.begin(), used.end(), name) == used.end();
  });
  device_manager_->onReading([this](const DeviceEntry& e, const Reading& r) {
    if (const auto* pose = std::get_if<procam_pose_sample>(&r)) {
      onTrackerSample(e.name, *pose);
    } else if (const auto* frame = std::get_if<CameraFrame>(&r)) {
      trackers_.stats[e.name].add(frame->timestamp_ns);
    }
  });
  device_manager_->onDeviceAdded([this](const DeviceEntry&) { syncTrackerPolls(); });
  device_manager_->onDeviceRemoved([this](const DeviceEntry&) { syncTrackerPolls(); });
  syncTrackerPolls();
  // Devices reopened by `reload` come without hooks: re-sync once a second.
  auto timer = loop_->addTimer(std::chrono::seconds(1), true, [this] { syncTrackerPolls(); });
  if (timer) {
    trackers_.sync_timer = *timer;
  } else {
    warn("trackers reopened by reload will not be polled: " + timer.error().message);
  }
}

void Daemon::syncTrackerPolls() {
  for (auto it = trackers_.polls.begin(); it != trackers_.polls.end();) {
    const DeviceEntry* e = devices_.find(it->first);
    if (e && e->usable() && e->device.pollFd() < 0) {
      ++it;
      continue;
    }
    device_manager_->stopPolling(it->second);
    it = trackers_.polls.erase(it);
  }
  // Trackers with a poll fd are read by the manager when it is readable.
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_TRACKER || !e.usable() || e.device.pollFd() >= 0 ||
        trackers_.polls.count(e.name)) {
      continue;
    }
    const auto period = std::chrono::nanoseconds(static_cast<int64_t>(1e9 / trackerPollHz(e)));
    if (auto id = device_manager_->pollEvery(e.name, period)) {
      trackers_.polls[e.name] = *id;
    } else {
      warn("tracker '" + e.name + "' is not read: " + id.error().message);
    }
  }
}

void Daemon::onTrackerSample(const std::string& name, const procam_pose_sample& s) {
  const Vec3 raw(s.position[0], s.position[1], s.position[2]);
  if (!raw.allFinite()) return;
  if (!trackers_.stats[name].add(s.timestamp_ns)) return;  // the same sample again
  TrackerPose& p = trackers_.latest[name];
  p.raw = raw;
  auto reg = trackers_.registrations.find(name);
  p.world = reg == trackers_.registrations.end() ? raw : reg->second.fit.toWorld(raw);
  p.timestamp_ns = s.timestamp_ns;
  p.received = std::chrono::steady_clock::now();
  if (name == mesh_follow_.tracker) onMeshViewerSample();
  if (name == object_show_.tracker) onObjectViewerSample();
  // Image content on a non-planar surface drawn by the two-pass path follows the viewer:
  // a new frame for the new eye (one at a time; refreshOutputs coalesces).
  for (const auto& [output, st] : keystone_rt_.output_state) {
    if (st.np_tracked && st.path == "two-pass-mesh") {
      refreshOutputs();
      break;
    }
  }
}

json Daemon::viewerJson() const {
  // The first tracker (in device order) that has reported: the viewer's head.
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_TRACKER) continue;
    auto it = trackers_.latest.find(e.name);
    if (it == trackers_.latest.end()) continue;
    return {{"position", vectorJson(it->second.world)},
            {"source", "tracker"},
            {"tracker", e.name},
            {"registered", trackers_.registrations.count(e.name) > 0},
            {"age_s", ageSeconds(it->second.received)}};
  }
  return nullptr;
}

void Daemon::addReadingStats(const DeviceEntry& e, json& entry) const {
  auto it = trackers_.stats.find(e.name);
  if (it == trackers_.stats.end()) return;
  const char* key = e.description.family == PROCAM_FAMILY_CAMERA ? "frames" : "samples";
  entry.update(it->second.toJson(key));
}

json Daemon::trackersJson() const {
  json list = json::array();
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_TRACKER) continue;
    json t = {{"name", e.name}, {"state", e.state()}, {"driver", e.driver}};
    auto reg = trackers_.registrations.find(e.name);
    t["registration"] =
        reg == trackers_.registrations.end() ? json(nullptr) : registrationJson(reg->second);
    if (auto it = trackers_.latest.find(e.name); it != trackers_.latest.end()) {
      t["position"] = vectorJson(it->second.world);
      t["raw"] = vectorJson(it->second.raw);
      t["age_s"] = ageSeconds(it->second.received);
    } else {
      t["position"] = t["raw"] = nullptr;
    }
    if (auto it = trackers_.stats.find(e.name); it != trackers_.stats.end()) {
      t.update(it->second.toJson("samples"));
    } else {
      t["samples"] = 0;
      t["rate_hz"] = 0;
    }
    list.push_back(std::move(t));
  }
  return list;
}

void Daemon::cmdTracker(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "tracker", "mode", "points", "origin", "x_axis", "viewer_side");
  const std::string action = args.string("action").value_or("get");
  auto named = args.string("tracker");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (action == "get") {
    replyTo(client, req, "TRACKER", {{"trackers", trackersJson()}, {"viewer", viewerJson()}});
    return;
  }
  if (action != "register") {
    return errorTo(client, req, code::kBadArgument, "\"action\" must be \"get\" or \"register\"");
  }
  std::string name;
  for (const auto& e : devices_.entries()) {
    if (e.description.family == PROCAM_FAMILY_TRACKER && (!named || e.name == *named)) {
      name = e.name;
      break;
    }
  }
  if (name.empty()) {
    return errorTo(client, req, code::kNotFound,
                   named ? "no tracker '" + *named + "'" : "this rig has no tracker");
  }
  auto fit = fitRegistrationRequest(req.body);
  if (!fit) return errorTo(client, req, errorCode(fit.error().code), fit.error().message);

  // In use at once; the file follows on the I/O worker, whose jobs run in order,
  // so the last write holds every registration made so far.
  std::optional<TrackerRegistrationRecord> previous;
  if (auto it = trackers_.registrations.find(name); it != trackers_.registrations.end()) {
    previous = it->second;
  }
  trackers_.registrations[name] = *fit;
  const uint64_t generation = ++trackers_.generation[name];
  if (auto it = trackers_.latest.find(name); it != trackers_.latest.end()) {
    it->second.world = fit->fit.toWorld(it->second.raw);
  }
  const std::string text = trackerFileText(trackers_.registrations);
  json reply = {{"tracker", name}, {"registration", registrationJson(*fit)}};
  io_worker_->submit(
      [this, dir = options_.state_dir, text, reply, client, req, name, generation, previous] {
        const StateFile file = trackerFile(dir);
        Result<void> ok = file.write(text);
        return [this, ok, reply, client, req, name, generation, previous,
                path = file.path()]() mutable {
          if (!ok) {
            // Undo this registration unless a later one replaced it meanwhile.
            if (trackers_.generation[name] == generation) {
              if (previous) {
                trackers_.registrations[name] = *previous;
              } else {
                trackers_.registrations.erase(name);
              }
            }
            return errorTo(client, req, code::kIo,
                           "tracker.json not written: " + ok.error().message);
          }
          reply["path"] = path;
          logInfo("tracker '" + name + "' registered (rms " +
                  std::to_string(reply["registration"]["rms_m"].get<double>() * 1e3) + " mm)");
          replyTo(client, req, "TRACKER", reply);
        };
      },
      [this, client, req](const std::string& what) {
        errorTo(client, req, code::kInternal, "tracker.json not written: " + what);
      },
      // The daemon's own lane, not the client's: registrations land in the order
      // they were made, whoever made them.
      0);
}

}  // namespace procam::daemon
