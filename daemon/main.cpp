// procamd: the projector-camera daemon (see daemon/PROTOCOL.md, ARCHITECTURE.md).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

#include "core/guarded_main.hpp"
#if defined(__SANITIZE_THREAD__)
#include <opencv2/core/utility.hpp>
#endif
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
    "  --version           print the release and exit\n";

std::string envOr(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  // systemd may pass several colon-separated directories: the first is ours.
  if (v && *v) return std::string(v).substr(0, std::string(v).find(':'));
  return fallback;
}

int listDrivers(const std::string& plugin_dir) {
  procam::plugins::DriverRegistry registry;
  std::vector<std::string> refused;
  auto statics = procam::plugins::loadStaticPlugins(procam::plugins::staticPlugins());
  if (!statics) {
    std::fprintf(stderr, "procamd: %s\n", statics.error().message.c_str());
    return 1;
  }
  registry.addAll(*statics, refused);
  std::vector<procam::Error> errors;
  registry.addAll(procam::plugins::loadPluginDirectory(plugin_dir, errors), refused);
  for (const auto& d : registry.drivers()) {
    std::printf("%-8s %-24s %s\n", procam::plugins::familyName(d.family()), d.name().c_str(),
                d.origin.c_str());
  }
  for (const auto& e : errors) std::fprintf(stderr, "procamd: %s\n", e.message.c_str());
  for (const auto& r : refused) std::fprintf(stderr, "procamd: %s\n", r.c_str());
  return errors.empty() && refused.empty() ? 0 : 1;
}

}  // namespace

static int run(int argc, char** argv) {
  procam::daemon::DaemonOptions opts;
  opts.runtime_dir = envOr("RUNTIME_DIRECTORY", "/run/procamd");
  opts.state_dir = envOr("STATE_DIRECTORY", "/var/lib/procamd");
  bool list = false;
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
