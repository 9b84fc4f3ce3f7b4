#include "daemon.hpp"

#include <grp.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include "loader.hpp"
#include "log.hpp"
#include "systemd_notify.hpp"

namespace procam::daemon {

namespace {

gid_t lookupGroup(const std::string& name) {
  if (name.empty()) return static_cast<gid_t>(-1);
  // Called once at start-up, before the loop runs.
  const group* g = ::getgrnam(name.c_str());
  return g ? g->gr_gid : static_cast<gid_t>(-1);
}

}  // namespace

Daemon::Daemon(DaemonOptions options) : options_(std::move(options)) {}

Daemon::~Daemon() {
  for (auto& [id, op] : operations_) op.cancelled->store(true);  // a running job stops early
  stopCameraYaw();                                               // so does the yaw's
  server_.reset();
  io_worker_.reset();  // a state write in progress ends first
  compute_worker_.reset();
  device_manager_.reset();
  devices_.closeAll();
  removeControlSocket(socket_info_);
}

Result<std::unique_ptr<Daemon>> Daemon::create(DaemonOptions options) {
  std::unique_ptr<Daemon> d(new Daemon(std::move(options)));
  if (auto ok = d->setup(); !ok) return tl::unexpected(ok.error());
  return d;
}

void Daemon::warn(const std::string& message) {
  // The same warning over and over (a device failing every read) is logged and
  // broadcast once per interval, with a count of the ones held back.
  auto& throttle = warn_throttles_.try_emplace(message, std::chrono::seconds(10), 5).first->second;
  auto line = throttle.pass(message);
  if (warn_throttles_.size() > 256) warn_throttles_.clear();  // bounded; forgets old ones
  if (!line) return;
  logWarning(*line);
  warnings_.push_back(message);
  if (warnings_.size() > 32) warnings_.erase(warnings_.begin());
  if (server_) broadcast("warning", {{"message", message}});
}

ContentAccess Daemon::contentAccess() const {
  ContentAccess a;
  a.roots = config_.content_roots;
  if (a.roots.empty()) a.roots.push_back(std::filesystem::absolute(options_.state_dir) / "content");
  a.limits = config_.limits;
  a.allow_pipeline = config_.content_allow_pipeline;
  return a;
}

ServerOptions Daemon::serverOptions() const {
  ServerOptions o;
  o.release = kRelease;
  o.max_clients = static_cast<size_t>(config_.max_clients);
  o.queue_limit_bytes = static_cast<size_t>(config_.client_queue_kib) * 1024;
  o.stall_timeout =
      std::chrono::milliseconds(static_cast<int64_t>(config_.client_stall_timeout_s * 1000.0));
  o.group = lookupGroup(config_.group);
  return o;
}

Result<void> Daemon::setup() {
  started_ = std::chrono::steady_clock::now();
  if (!options_.config_path.empty()) {
    auto cfg = loadConfig(options_.config_path);
    if (!cfg) return tl::unexpected(cfg.error());
    config_ = std::move(*cfg);
  }
  setLogLevel(config_.log_level);
  if (options_.sim_scene.empty()) options_.sim_scene = config_.sim_scene;
  // OpenCV's own decoder bound (read once, before any thread exists), behind the
  // header check of content/image_header.hpp: a format whose header a decoder
  // reads differently still cannot allocate past the configured limit.
  ::setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(config_.limits.image_pixels).c_str(), 0);

  auto loop = EventLoop::create();
  if (!loop) return tl::unexpected(loop.error());
  loop_ = std::move(*loop);
  // Signals are blocked before any thread exists so that only signalfd sees them.
  if (auto ok = loop_->watchSignals({SIGTERM, SIGINT, SIGHUP}, [this](int s) { onSignal(s); });
      !ok) {
    return ok;
  }
  ::signal(SIGPIPE, SIG_IGN);

  std::error_code ec;
  std::filesystem::create_directories(options_.runtime_dir, ec);
  if (ec) {
    return fail(ErrorCode::kIo,
                "cannot create runtime directory " + options_.runtime_dir + ": " + ec.message());
  }
  const ServerOptions server_options = serverOptions();
  auto sock = openControlSocket(options_.runtime_dir + "/control.sock", server_options.group);
  if (!sock) return tl::unexpected(sock.error());
  socket_info_.activated = sock->activated;
  socket_info_.path = sock->path;

  settings_file_ = std::make_unique<StateFile>(options_.state_dir, "settings.json",
                                               [](std::string_view text) -> Result<void> {
                                                 auto s = settingsFromJson(text);
                                                 if (!s) return tl::unexpected(s.error());
                                                 return {};
                                               });
  if (auto ok = settings_file_->ensureDirectory(); !ok) return ok;
  // The default content root, made here so that an installer finds where content goes.
  if (config_.content_roots.empty()) {
    std::filesystem::create_directory(options_.state_dir + "/content", ec);
    if (!ec)
      std::filesystem::permissions(options_.state_dir + "/content", std::filesystem::perms(0750),
                                   ec);
  }
  loadSettings();
  if (auto ok = loadRigModel(); !ok) return ok;
  loadDrivers();
  if (!options_.sim_scene.empty()) {
    if (auto ok = openVirtualRig(); !ok) return ok;
  }
  openDevices();
  device_manager_ = std::make_unique<DeviceManager>(
      *loop_, registry_, devices_,
      [this](const std::string& event, nlohmann::json body) {
        if (server_) broadcast(event, std::move(body));
      },
      [this](const std::string& message) { warn(message); });
  // The virtual rig is the whole rig: no discovery of real devices beside it.
  device_manager_->start({.udev = options_.sim_scene.empty()});

  io_worker_ = std::make_unique<WorkerPool>(*loop_, 1);
  io_worker_->runQueuedOnStop();  // saves asked for before a stop are written
  compute_worker_ = std::make_unique<WorkerPool>(*loop_, 1);
  server_ = std::make_unique<ControlServer>(
      *loop_, std::move(sock->fd), server_options,
      [this](ClientId c, const proto::Request& r) { handle(c, r); },
      [this](ClientId c) { onDisconnect(c); });
  if (auto ok = server_->start(); !ok) return ok;
  setupAutoKeystone();
  setupTrackers();
  watchObjectOutputs();
  setupDriftCheck();
  loadRigSurfaces();
  loadContentAtStart();
  refreshOutputs();

  if (auto ok = loop_->addTimer(std::chrono::seconds(1), true, [this] { housekeeping(); }); !ok) {
    return tl::unexpected(ok.error());
  }
  if (auto interval = watchdogPingInterval()) {
    // Pinged from the loop itself: a stuck loop stops the pings.
    auto ok = loop_->addTimer(*interval, true, [] { notifyWatchdog(); });
    if (!ok) return tl::unexpected(ok.error());
  }
  return {};
}

void Daemon::loadSettings() {
  auto loaded = settings_file_->read();
  if (!loaded) {
    if (loaded.error().code != ErrorCode::kNotFound) {
      warn("settings not restored: " + loaded.error().message + "; using defaults");
    }
    return;
  }
  if (loaded->from_backup) warn(loaded->warning);
  // The validator already accepted the text.
  settings_ = *settingsFromJson(loaded->contents);
}

void Daemon::loadDrivers() {
  auto statics = plugins::loadStaticPlugins(plugins::staticPlugins());
  std::vector<std::string> refused;
  if (statics) {
    registry_.addAll(*statics, refused);
  } else {
    warn("in-tree drivers: " + statics.error().message);
  }
  std::string dir = options_.plugin_dir;
  if (dir.empty()) dir = config_.plugin_dir;
  if (dir.empty()) dir = PROCAM_DEFAULT_PLUGIN_DIR;
  std::vector<Error> errors;
  registry_.addAll(plugins::loadPluginDirectory(dir, errors), refused);
  for (const auto& e : errors) warn(e.message);
  for (const auto& r : refused) warn(r);
  logInfo(std::to_string(registry_.drivers().size()) + " driver(s) available");
}

Result<void> Daemon::loadRigModel() {
  if (!options_.rig_path.empty()) {
    auto imported = importRig(options_.state_dir, options_.rig_path);
    if (!imported) return fail(imported.error().code, "--rig: " + imported.error().message);
    rig_ = std::move(*imported);
    logInfo("rig model from " + options_.rig_path + ": " + std::to_string(rig_.cameras.size()) +
            " camera(s), " + std::to_string(rig_.projectors.size()) + " projector(s)");
    return {};
  }
  auto loaded = loadRig(options_.state_dir);
  if (!loaded) {
    // A damaged rig is not fatal: the daemon runs without geometry until calibrate.
    warn("rig model not loaded: " + loaded.error().message);
    return {};
  }
  if (!loaded->warning.empty()) warn(loaded->warning);
  rig_ = std::move(loaded->rig);
  if (rig_.empty()) {
    logInfo("no rig model yet (" + loaded->path + "): calibrate writes it");
  } else {
    logInfo("rig model " + loaded->path + ": " + std::to_string(rig_.cameras.size()) +
            " camera(s), " + std::to_string(rig_.projectors.size()) + " projector(s)");
  }
  return {};
}

// The virtual rig is a set of drivers like any other: every driver that lists
// devices by itself is asked for the scene's, and each is opened through
// probe/create. The daemon learns nothing of the scene but the devices.
Result<void> Daemon::openVirtualRig() {
  const std::vector<std::pair<std::string, std::string>> options = {{"scene", options_.sim_scene}};
  size_t opened = 0;
  for (const plugins::Driver& driver : registry_.drivers()) {
    auto listed = plugins::enumerateDevices(driver, options);
    if (!listed) return tl::unexpected(listed.error());
    for (auto& desc : *listed) {
      const DeviceEntry& e = devices_.open(registry_, std::move(desc), driver.name(), {});
      if (!e.usable()) {
        return fail(ErrorCode::kIo, "virtual rig device '" + e.name + "': " + e.error);
      }
      ++opened;
    }
  }
  if (opened == 0) {
    return fail(ErrorCode::kNotFound, "no driver provides the virtual rig '" + options_.sim_scene +
                                          "' (built without the simulator?)");
  }
  logInfo("virtual rig '" + options_.sim_scene + "': " + std::to_string(opened) + " device(s)");
  return {};
}

void Daemon::openDevices() {
  for (const DeviceConfig& dc : config_.devices) {
    plugins::DeviceDescription desc;
    desc.family = dc.family;
    desc.name = dc.name;
    desc.devnode = dc.devnode;
    desc.subsystem = "config";
    // The role a udev rule would give such a device (udev/70-procamd.rules).
    desc.properties = {{"PROCAM_ROLE", plugins::familyName(dc.family)}};
    const DeviceEntry& e = devices_.open(registry_, desc, dc.driver, dc.options);
    if (e.usable()) {
      logInfo("opened " + std::string(plugins::familyName(dc.family)) + " '" + dc.name +
              "' with driver " + e.driver);
    } else {
      warn(config_.source + ":" + std::to_string(dc.line) + ": device '" + dc.name +
           "': " + e.error);
    }
  }
}

void Daemon::onSignal(int signo) {
  if (signo == SIGHUP) {
    if (auto ok = reloadConfig(); !ok) {
      warn("reload on SIGHUP failed, keeping the previous configuration: " + ok.error().message);
    }
    return;
  }
  logInfo(std::string("stopping on ") + (signo == SIGINT ? "SIGINT" : "SIGTERM"));
  notifyStopping();
  loop_->stop(0);
}

void Daemon::housekeeping() {
  server_->checkStalls();
}

int Daemon::run() {
  const std::string where = socket_info_.activated ? "socket passed by systemd" : socket_info_.path;
  std::string status = "ready: " + std::to_string(devices_.entries().size()) + " device(s), " +
                       "control on " + where;
  logInfo("procamd " + std::string(kRelease) + " " + status);
  notifyReady(status);
  return loop_->run();
}

}  // namespace procam::daemon
