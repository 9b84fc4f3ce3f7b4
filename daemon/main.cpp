// procamd: the projector-camera daemon (see daemon/PROTOCOL.md, ARCHITECTURE.md).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <thread>

#include "core/guarded_main.hpp"
#if defined(__SANITIZE_THREAD__)
#include <opencv2/core/utility.hpp>
#endif
#include "config.hpp"
#include "daemon.hpp"
#include "loader.hpp"
#include "log.hpp"
#include "registry.hpp"

namespace {

// What a stop may take once the loop has ended; systemd's TimeoutStopSec is far
// longer, but a service that is told to stop should be gone in 2 s.
constexpr std::chrono::milliseconds kStopDeadline{1500};

// `--sim` without a scene: a handheld projector with an accelerometer.
constexpr const char* kDefaultSimScene = "handheld";

constexpr const char* kUsage =
    "usage: procamd [options]\n"
    "  --config PATH       configuration (default /etc/procamd/procamd.toml when it exists)\n"
    "  --sim [SCENE]       run on the virtual rig: a shipped scene name or a file\n"
    "                      (default: handheld); selects the mock drivers only: the\n"
    "                      geometry comes from the rig model, as on hardware\n"
    "  --rig FILE          install FILE (a rig.json, e.g. from procam-sim truth\n"
    "                      --rig-json) as the state directory's rig model at start\n"
    "  --runtime-dir DIR   control socket directory (default $RUNTIME_DIRECTORY or /run/procamd)\n"
    "  --state-dir DIR     saved settings (default $STATE_DIRECTORY or /var/lib/procamd)\n"
    "  --plugin-dir DIR    driver plugins (default " PROCAM_DEFAULT_PLUGIN_DIR
    ")\n"
    "  --list-drivers      print the available drivers and exit\n"
    "  --check-config FILE check a configuration without starting: syntax, keys,\n"
    "                      values, the group and every named driver; exit 0 when\n"
    "                      it is valid, 1 with file:line: key: problem otherwise\n"
    "  --version           print the release and exit\n";

std::string envOr(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  // systemd may pass several colon-separated directories: the first is ours.
  if (v && *v) return std::string(v).substr(0, std::string(v).find(':'));
  return fallback;
}

// The built-in drivers and those of the plugin directory; refusals and load errors
// are appended to `problems`.
procam::plugins::DriverRegistry loadRegistry(const std::string& plugin_dir,
                                             std::vector<std::string>& problems) {
  procam::plugins::DriverRegistry registry;
  auto statics = procam::plugins::loadStaticPlugins(procam::plugins::staticPlugins());
  if (!statics) {
    problems.push_back(statics.error().message);
    return registry;
  }
  registry.addAll(*statics, problems);
  std::vector<procam::Error> errors;
  registry.addAll(procam::plugins::loadPluginDirectory(plugin_dir, errors), problems);
  for (const auto& e : errors) problems.push_back(e.message);
  return registry;
}

int listDrivers(const std::string& plugin_dir) {
  std::vector<std::string> problems;
  const auto registry = loadRegistry(plugin_dir, problems);
  for (const auto& d : registry.drivers()) {
    std::printf("%-8s %-24s %s\n", procam::plugins::familyName(d.family()), d.name().c_str(),
                d.origin.c_str());
  }
  for (const auto& p : problems) std::fprintf(stderr, "procamd: %s\n", p.c_str());
  return problems.empty() ? 0 : 1;
}

// What the service's ExecStartPre= and an installer run: everything start-up would
// refuse in the file, without a socket, a device or a state directory.
int checkConfig(const std::string& path, const std::string& plugin_dir_option) {
  auto cfg = procam::daemon::loadConfig(path);
  if (!cfg) {
    std::fprintf(stderr, "%s\n", cfg.error().message.c_str());
    return 1;
  }
  std::string plugin_dir = plugin_dir_option;
  if (plugin_dir.empty()) plugin_dir = cfg->plugin_dir;
  if (plugin_dir.empty()) plugin_dir = PROCAM_DEFAULT_PLUGIN_DIR;
  std::vector<std::string> problems;
  const auto registry = loadRegistry(plugin_dir, problems);
  // A plugin directory that cannot be read is a warning at start-up, not a refusal.
  for (const auto& p : problems) std::fprintf(stderr, "procamd: warning: %s\n", p.c_str());
  int bad = 0;
  std::map<procam_family, int> index;  // the device's place in its [[family]] array
  for (const auto& d : cfg->devices) {
    const int i = index[d.family]++;
    if (d.driver.empty() || registry.find(d.family, d.driver)) continue;
    // The configuration's arrays: [[projector]] holds output devices.
    const char* family =
        d.family == PROCAM_FAMILY_OUTPUT ? "projector" : procam::plugins::familyName(d.family);
    std::fprintf(stderr, "%s:%d: %s[%d].driver: no %s driver named '%s' is built in or in %s\n",
                 path.c_str(), d.driver_line, family, i, family, d.driver.c_str(),
                 plugin_dir.c_str());
    ++bad;
  }
  if (bad > 0) return 1;
  std::printf("%s: valid (%zu device%s configured)\n", path.c_str(), cfg->devices.size(),
              cfg->devices.size() == 1 ? "" : "s");
  return 0;
}

}  // namespace

static int run(int argc, char** argv) {
  procam::daemon::DaemonOptions opts;
  opts.runtime_dir = envOr("RUNTIME_DIRECTORY", "/run/procamd");
  opts.state_dir = envOr("STATE_DIRECTORY", "/var/lib/procamd");
  bool list = false;
  std::string check_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](std::string& out) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "procamd: %s needs a value\n%s", a.c_str(), kUsage);
        std::exit(2);
      }
      out = argv[++i];
    };
    if (a == "--config") {
      value(opts.config_path);
    } else if (a == "--sim") {
      // The scene is optional: the shipped handheld rig by default.
      if (i + 1 < argc && argv[i + 1][0] != '-') {
        opts.sim_scene = argv[++i];
      } else {
        opts.sim_scene = kDefaultSimScene;
      }
    } else if (a == "--rig") {
      value(opts.rig_path);
    } else if (a == "--runtime-dir") {
      value(opts.runtime_dir);
    } else if (a == "--state-dir") {
      value(opts.state_dir);
    } else if (a == "--plugin-dir") {
      value(opts.plugin_dir);
    } else if (a == "--list-drivers") {
      list = true;
    } else if (a == "--check-config") {
      value(check_path);
    } else if (a == "--version") {
      std::printf("procamd %s (control protocol %d.%d, plugin ABI %u)\n", procam::daemon::kRelease,
                  procam::daemon::proto::kMajor, procam::daemon::proto::kMinor,
                  PROCAM_PLUGIN_ABI_VERSION);
      return 0;
    } else if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else {
      std::fprintf(stderr, "procamd: unknown option '%s'\n%s", a.c_str(), kUsage);
      return 2;
    }
  }
  if (!check_path.empty()) return checkConfig(check_path, opts.plugin_dir);
  if (list)
    return listDrivers(opts.plugin_dir.empty() ? PROCAM_DEFAULT_PLUGIN_DIR : opts.plugin_dir);
  if (opts.config_path.empty() && opts.sim_scene.empty() &&
      ::access("/etc/procamd/procamd.toml", F_OK) == 0) {
    opts.config_path = "/etc/procamd/procamd.toml";
  }
  auto daemon = procam::daemon::Daemon::create(opts);
  if (!daemon) {
    procam::daemon::logError("procamd: " + daemon.error().message);
    return 1;
  }
  const int rc = (*daemon)->run();
  // Releasing devices may block in their libraries (libaravis waits on a dead
  // camera for many seconds): the teardown writes the queued state first (every
  // write is atomic: one cut short leaves the previous file), and a stop never
  // waits past the deadline for the devices.
  std::thread([rc] {
    std::this_thread::sleep_for(kStopDeadline);
    procam::daemon::logWarning("devices not released within " +
                               std::to_string(kStopDeadline.count()) +
                               " ms of the stop: exiting without them");
    std::_Exit(rc);
  }).detach();
  daemon->reset();
  return rc;
}

int main(int argc, char** argv) {
#if defined(__SANITIZE_THREAD__)
  // OpenCV runs its parallel loops on TBB's threads, whose synchronisation
  // ThreadSanitizer cannot see (libtbb is not instrumented): in a TSan build the
  // loops run on the calling thread, so that reports are about procamd's threads.
  cv::setNumThreads(0);
#endif
  return procam::guardedMain("procamd", [&] { return run(argc, argv); });
}
