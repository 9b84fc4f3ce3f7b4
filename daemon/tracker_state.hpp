#pragma once
// Trackers in the daemon (PROTOCOL.md "Trackers"): the latest reading of every
// tracker, raw and in the world frame, and the tracker -> world registrations
// ([Raskar02] §4.1.2 "Tracked Viewer Registration", eq. 4.2, §4.2.5) that the
// `tracker register` command fits and <state-dir>/tracker.json keeps beside
// rig.json. Pure data and JSON here; daemon_tracker.cpp does the reading.
#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "core/error.hpp"
#include "core/types.hpp"
#include "reading_stats.hpp"
#include "tracking/tracker_registration.hpp"

namespace procam::daemon {

inline constexpr const char* kTrackerFile = "tracker.json";

struct TrackerRegistrationRecord {
  tracking::TrackerRegistration fit;
  std::string source;  // how it was measured: "points" (eq. 4.2) or "screen" (§4.2.5)
  int points = 0;      // readings it was fitted to
};
using TrackerRegistrations = std::map<std::string, TrackerRegistrationRecord>;

struct TrackerPose {
  Vec3 raw = Vec3::Zero();    // as the tracker reported it
  Vec3 world = Vec3::Zero();  // after its registration (raw without one)
  uint64_t timestamp_ns = 0;  // the tracker's
  std::chrono::steady_clock::time_point received;
};

// The daemon's tracker and camera reading state (loop thread only).
struct TrackerRuntime {
  std::map<std::string, TrackerPose> latest;   // tracker name -> last pose
  std::map<std::string, ReadingStats> stats;   // tracker or camera name -> its readings
  TrackerRegistrations registrations;          // tracker name -> registration
  std::map<std::string, int> polls;            // tracker name -> DeviceManager::pollEvery id
  std::map<std::string, uint64_t> generation;  // of each registration: writes finish in order
  int sync_timer = -1;
};

// {source, rms_m, points, scale, R (9, rows), t}: the fit x_world = s R x_tracker + t.
nlohmann::json registrationJson(const TrackerRegistrationRecord& r);
// tracker.json: {"trackers": {name: registrationJson, ...}}.
std::string trackerFileText(const TrackerRegistrations& registrations);
// kParse naming the tracker and key for anything malformed (R not a rotation too).
Result<TrackerRegistrations> trackerFileFromText(std::string_view text);

// A `tracker register` request's points and mode, fitted. kInvalidInput for a
// malformed request (the message names the key); the fit's own kTooFewPoints
// and kDegenerate otherwise.
Result<TrackerRegistrationRecord> fitRegistrationRequest(const nlohmann::json& request);

}  // namespace procam::daemon
