#pragma once
// procamd.toml: the rig (projectors, cameras, tilt sensors, trackers, their
// drivers and options) and the daemon's policies. Every unknown key and every
// bad value is an error naming the file, line and key.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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
};

enum class RecalibratePolicy { kOff, kOnDrift };

struct Config {
  std::string source;  // file name, for messages
  LogLevel log_level = LogLevel::kInfo;
  std::string plugin_dir;  // empty: the built-in default
  std::string group = "procam";
  int max_clients = 128;
  int client_queue_kib = 1024;
  double client_stall_timeout_s = 10.0;
  bool auto_keystone = false;
  RecalibratePolicy recalibrate = RecalibratePolicy::kOff;
  std::string sim_scene;
  std::vector<DeviceConfig> devices;
};

// Parses TOML text; `source` names it in messages. All problems found are
// reported, one per line, in the error message.
Result<Config> parseConfig(std::string_view text, const std::string& source);
Result<Config> loadConfig(const std::string& path);

const char* recalibratePolicyName(RecalibratePolicy policy);

}  // namespace procam::daemon
