#pragma once
// procamd.toml: the rig (projectors, cameras, tilt sensors, trackers, their
// drivers and options) and the daemon's policies. Every unknown key and every
// bad value is an error naming the file, line and key.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "content_access.hpp"
#include "core/error.hpp"
#include "log.hpp"
#include "procamd/procam_plugin.h"

namespace procam::daemon {

struct DeviceConfig {
  procam_family family = PROCAM_FAMILY_CAMERA;
  std::string name;
  std::string driver;                                        // empty: the best-scoring driver
  std::string devnode;                                       // empty: any device of the family
  std::vector<std::pair<std::string, std::string>> options;  // values as text
  int line = 0;
  int driver_line = 0;  // where `driver` was given
};

// "on-drift-silent" watches and corrects as "on-drift" does, but never shows a frame of
// its own (no fiducial frame when the content is too plain).
enum class RecalibratePolicy { kOff, kOnDrift, kOnDriftSilent };
inline bool watchesDrift(RecalibratePolicy p) {
  return p == RecalibratePolicy::kOnDrift || p == RecalibratePolicy::kOnDriftSilent;
}

// [keystone]: the automatic keystone loop (keystone/tilt_tracker.hpp), read by
// daemon/auto_keystone.hpp.
struct KeystoneConfig {
  double cutoff_hz = 10.0;       // tilt low-pass cut-off
  double hysteresis_deg = 0.02;  // re-solve only when gravity turns by more than this
  double poll_hz = 100.0;        // timer rate for tilt sensors without a poll fd
  // The yaw a tilt sensor cannot see, from the camera mounted on the projector (rig.json
  // `attached_to`): at each still hold the projector shows a dot grid for `yaw_frames`
  // camera frames ([Raskar02] §6.2.2).
  bool camera_yaw = true;
  int yaw_frames = 64;
  // Sensor -> projector mounting (row i = sensor axis i in projector axes) and the
  // six-position accelerometer calibration (offset in g, per-axis gain); the
  // virtual rig takes the mount from its scene and calibrates at start.
  std::optional<std::array<double, 9>> mount;
  std::array<double, 3> accel_offset_g{0, 0, 0};
  std::array<double, 3> accel_scale{1, 1, 1};
  // The display across several projectors on one wall: its centre (world, metres, on the
  // wall) and size (width, height on the wall, metres) instead of the largest rectangle.
  std::optional<std::array<double, 3>> display_centre;
  std::optional<std::array<double, 2>> display_size;
};

// [calibration]: the settle wait of `calibrate` and the display-to-capture latency
// probe (daemon/latency_probe.hpp).
struct CalibrationConfig {
  int settle_frames = 2;           // output frames waited after showing a pattern
  bool auto_settle = false;        // settle_frames = "auto": measure the latency first
  int margin_frames = 1;           // added to ceil(latency * refresh) by "auto"
  int latency_repeats = 3;         // black/white cycles per camera
  double latency_timeout_s = 1.0;  // the longest latency looked for
};

// [policy] drift_*: the drift check and correction of recalibrate = "on-drift"
// (daemon/daemon_drift.cpp).
struct DriftConfig {
  double period_s = 0.25;     // between two checks (one output per check, in turn)
  double threshold_px = 0.5;  // misregistration (RMS, projector pixels) that is drift
  double settle_s = 0.5;      // held this long before a correction
  int frames = 2;             // camera frames averaged per check
  // "on-drift" with content too plain to register: a fiducial frame at most this often
  // per output (and at every check while drift it saw is being confirmed); 0: never.
  double fiducial_period_s = 10.0;
  // "on-drift-silent" while a stream plays: its frame held on the outputs for a content
  // check at most this often per output (and at every check while drift it saw is being
  // confirmed); 0: never.
  double stream_period_s = 5.0;
};

struct Config {
  std::string source;  // file name, for messages
  LogLevel log_level = LogLevel::kInfo;
  std::string plugin_dir;  // empty: the built-in default
  std::string group = "procam";
  int group_line = 0;  // where the file set it (0: the default, which may be absent)
  int max_clients = 128;
  int client_queue_kib = 1024;
  double client_stall_timeout_s = 10.0;
  bool auto_keystone = false;
  RecalibratePolicy recalibrate = RecalibratePolicy::kOff;
  DriftConfig drift;
  std::string sim_scene;
  // [content] viewer: the viewer's eye (world, metres) for 3D content when no tracker
  // has reported one.
  std::optional<std::array<double, 3>> content_viewer;
  // [content] projection: what image content is on a non-planar display. "perspective"
  // (the default): the image the viewer at the sweet spot sees through a pinhole;
  // "dome": a dome master (render/dome_master.hpp) around that eye, its front toward
  // dome_front, dome_fov_deg wide, drawn for that eye whether or not a tracker reports.
  bool content_dome = false;
  std::array<double, 3> content_dome_front{0.0, 1.0, 0.0};
  double content_dome_fov_deg = 180.0;
  // [content] viewer_threshold_m: a tracked viewer who moved this far since the mesh was
  // last drawn has it drawn again (content_follow.cpp says why 5 mm).
  double content_viewer_threshold_m = 0.005;
  // [content] roots: where clients may take content from (empty: the state
  // directory's content/); allow_pipeline: raw gst-launch text from clients.
  std::vector<std::string> content_roots;
  bool content_allow_pipeline = false;
  ContentLimits limits;  // [limits]
  KeystoneConfig keystone;
  CalibrationConfig calibration;
  std::vector<DeviceConfig> devices;
};

// Parses TOML text; `source` names it in messages. All problems found are
// reported, one per line, in the error message.
Result<Config> parseConfig(std::string_view text, const std::string& source);
// Reads a regular file of at most kMaxConfigBytes (never a FIFO or device, which
// could block or never end), parses it, and checks what only this machine can
// tell: that a configured group exists.
inline constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;
Result<Config> loadConfig(const std::string& path);

const char* recalibratePolicyName(RecalibratePolicy policy);

}  // namespace procam::daemon
