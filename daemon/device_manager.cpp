#include "device_manager.hpp"

#include <sys/epoll.h>

#include <array>

#include "log.hpp"
#include "udev_monitor.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

std::string describeFamily(const DeviceEntry& e) {
  return std::string(plugins::familyName(e.description.family)) + " '" + e.name + "'";
}

}  // namespace

DeviceManager::ReadResult DeviceManager::readOnce(const procam_device& raw, procam_family family) {
  ReadResult r;
  std::array<char, 256> err{};
  switch (family) {
    case PROCAM_FAMILY_TILT: {
      TiltReading t;
      r.rc = raw.ops.tilt->read(raw.self, &t.sample, err.data(), err.size() - 1);
      if (r.rc == PROCAM_OK) t.rate = plugins::tiltRate(raw);
      r.reading = t;
      break;
    }
    case PROCAM_FAMILY_TRACKER: {
      procam_pose_sample s{};
      r.rc = raw.ops.tracker->read(raw.self, &s, err.data(), err.size() - 1);
      r.reading = s;
      break;
    }
    case PROCAM_FAMILY_CAMERA: {
      procam_image img{};
      r.rc = raw.ops.camera->capture(raw.self, 0, &img, err.data(), err.size() - 1);
      r.reading = CameraFrame{img.width, img.height, img.format, img.timestamp_ns};
      break;
    }
    case PROCAM_FAMILY_OUTPUT:
      break;
  }
  if (r.rc != PROCAM_OK) {
    r.reason = err[0] ? err.data() : "read failed (code " + std::to_string(r.rc) + ")";
  }
  return r;
}

DeviceManager::DeviceManager(EventLoop& loop, const plugins::DriverRegistry& registry,
                             DeviceSet& devices, EventSink emit, WarnSink warn)
    : loop_(loop),
      registry_(registry),
      devices_(devices),
      emit_(std::move(emit)),
      warn_(std::move(warn)),
      opener_(std::make_unique<WorkerPool>(loop, 1)),
      reader_(std::make_unique<WorkerPool>(loop, 1)),
      closer_(std::make_unique<WorkerPool>(loop, 1)) {}

DeviceManager::~DeviceManager() {
  opener_.reset();
  reader_.reset();  // a read still running ends first; its result is dropped
  closer_.reset();  // a release still running ends first
  *alive_ = false;
  for (const auto& [name, fd] : watched_) loop_.remove(fd);
  for (const auto& [id, name] : polls_) loop_.removeTimer(id);
  for (const auto& [name, r] : retries_) {
    if (r.timer >= 0) loop_.removeTimer(r.timer);
  }
  if (presence_timer_ >= 0) loop_.removeTimer(presence_timer_);
  if (monitor_) loop_.remove(monitor_->fd());
}

std::chrono::seconds DeviceManager::retryDelay(int attempt) {
  static constexpr std::array<int, 4> kFirst{1, 2, 4, 8};
  if (attempt >= 0 && attempt < static_cast<int>(kFirst.size())) {
    return std::chrono::seconds(kFirst[static_cast<size_t>(attempt)]);
  }
  return std::chrono::seconds(10);
}

std::function<void()> DeviceManager::guarded(std::function<void()> fn) const {
  return [alive = std::weak_ptr<bool>(alive_), fn = std::move(fn)] {
    if (auto a = alive.lock(); a && *a) fn();
  };
}

void DeviceManager::onDeviceAdded(DeviceCallback callback) {
  on_added_.push_back(std::move(callback));
}
void DeviceManager::onDeviceRemoved(DeviceCallback callback) {
  on_removed_.push_back(std::move(callback));
}
void DeviceManager::onReading(ReadingCallback callback) {
  on_reading_.push_back(std::move(callback));
}
void DeviceManager::setReadGate(std::function<bool(const std::string&)> may_read) {
  may_read_ = std::move(may_read);
}

// --- start-up and hotplug ---

void DeviceManager::start(const DeviceManagerOptions& options) {
  presence_interval_ = options.presence_interval;
  for (const auto& e : devices_.entries()) watchFd(e);
  if (options.udev) {
    auto udev = Udev::create();
    if (!udev) {
      warn_("device discovery off: " + udev.error().message);
    } else {
      udev_ = std::make_unique<Udev>(std::move(*udev));
      enumerate();
      auto monitor = UdevMonitor::create(*udev_);
      if (!monitor) {
        warn_("hotplug off: " + monitor.error().message);
      } else {
        monitor_ = std::make_unique<UdevMonitor>(std::move(*monitor));
        auto ok = loop_.add(monitor_->fd(), EPOLLIN, [this](uint32_t) {
          while (auto record = monitor_->receive()) handleUdevEvent(*record);
        });
        if (!ok) {
          warn_("hotplug off: " + ok.error().message);
          monitor_.reset();
        }
      }
    }
  }
  auto timer = loop_.addTimer(options.presence_interval, true, [this] { presenceCheck(); });
  if (timer) {
    presence_timer_ = *timer;
  } else {
    warn_("presence checks off: " + timer.error().message);
  }
}

void DeviceManager::enumerate() {
  auto records = udev_->enumerate();
  if (!records) {
    warn_("device discovery failed: " + records.error().message);
    return;
  }
  size_t found = 0;
  for (const UdevRecord& r : *records) {
    if (auto desc = describeUdevDevice(r)) {
      ++found;
      openDiscovered(std::move(*desc), false);
    }
  }
  logInfo("udev: " + std::to_string(found) + " device(s) with a procamd role");
}

void DeviceManager::handleUdevEvent(const UdevRecord& record) {
  if (record.action == "remove") {
    pending_.erase(record.syspath);  // an open still running is dropped when it ends
    if (DeviceEntry* e = devices_.findBySyspath(record.syspath)) removeUnplugged(e->name);
    return;
  }
  if (record.action != "add") return;
  auto desc = describeUdevDevice(record);
  if (!desc) return;
  if (DeviceEntry* e = devices_.findBySyspath(desc->syspath)) {
    // A lost device that udev announces again: try it now.
    if (e->lost) {
      e->retries = 0;
      retry(e->name, retries_[e->name].token);
    }
    return;
  }
  openDiscovered(std::move(*desc), true);
}

void DeviceManager::openDiscovered(plugins::DeviceDescription desc, bool async) {
  // A configured device with this node keeps it (config wins over discovery).
  if (DeviceEntry* e = devices_.findByDevnode(desc.devnode);
      e && e->description.subsystem == "config") {
    logDebug("udev: " + desc.devnode + " is the configured device '" + e->name + "'");
    return;
  }
  if (devices_.findBySyspath(desc.syspath) || pending_.count(desc.syspath)) return;
  if (!async) {
    addDiscovered(DeviceSet::prepare(registry_, std::move(desc), "", {}));
    return;
  }
  const std::string syspath = desc.syspath;
  pending_.insert(syspath);
  opener_->submit([this, desc = std::move(desc), syspath]() mutable -> WorkerPool::Completion {
    auto entry =
        std::make_shared<DeviceEntry>(DeviceSet::prepare(registry_, std::move(desc), "", {}));
    return guarded([this, entry, syspath] {
      if (pending_.erase(syspath) == 0) {  // unplugged while opening
        retire(entry->device.share());
        entry->device.reset();
        return;
      }
      addDiscovered(std::move(*entry));
    });
  });
}

void DeviceManager::addDiscovered(DeviceEntry entry) {
  // Names are unique in the set: a configured device may already use the sysname.
  if (devices_.find(entry.name)) entry.name += "@" + entry.description.subsystem;
  const std::string name = entry.name;
  DeviceEntry& e = devices_.add(std::move(entry));
  if (e.usable()) {
    logInfo("opened " + describeFamily(e) + " (" + e.description.devnode + ") with driver " +
            e.driver);
    watchFd(e);
  } else {
    // Listed with the reason; not a warning: a rig has devices procamd does not drive.
    logInfo("not opened: " + describeFamily(e) + " (" + e.description.devnode + "): " + e.error);
  }
  emit_("device-added", e.toJson());
  if (devices_.find(name)->usable()) added(name);
}

void DeviceManager::removeUnplugged(const std::string& name) {
  cancelRetry(name);
  unwatchFd(name);
  DeviceEntry* e = devices_.find(name);
  if (!e) return;
  json body = e->toJson();
  body["state"] = "removed";
  retire(e->device.share());
  e->device.reset();  // the set's reference; a worker's share ends with its job
  last_frame_.erase(name);
  e->error = "unplugged";
  logInfo("unplugged: " + describeFamily(*e));
  removed(name);
  devices_.close(name);
  emit_("device-removed", std::move(body));
}

// --- lost devices ---

void DeviceManager::report(const std::string& name, int rc, const std::string& reason) {
  if (rc == PROCAM_OK || rc == PROCAM_EAGAIN) return;
  DeviceEntry* e = devices_.find(name);
  if (!e || !e->usable()) return;
  if (rc == PROCAM_ENODEV) {
    markLost(name, reason.empty() ? "the device is gone" : reason);
  } else if (rc == PROCAM_EEND) {
    markEnded(name, reason.empty() ? "its stream ended" : reason);
  } else {
    logDebug(describeFamily(*e) + ": error " + std::to_string(rc) + ": " + reason);
  }
}

void DeviceManager::markLost(const std::string& name, const std::string& reason) {
  unwatchFd(name);
  DeviceEntry* e = devices_.find(name);
  if (!e) return;
  retire(e->device.share());
  e->device.reset();
  e->lost = true;
  e->retries = 0;
  e->error = "lost: " + reason;
  warn_(describeFamily(*e) + " lost (" + reason + "); reopening in " +
        std::to_string(retryDelay(0).count()) + " s");
  emit_("device-removed", e->toJson());
  removed(name);
  scheduleRetry(name);
}

// Closed like a lost device, but there is nothing to reopen: a recording that
// played to its end stays ended until `reload` (or a restart) opens it again.
void DeviceManager::markEnded(const std::string& name, const std::string& reason) {
  unwatchFd(name);
  DeviceEntry* e = devices_.find(name);
  if (!e) return;
  retire(e->device.share());
  e->device.reset();
  e->ended = true;
  e->error = "ended: " + reason;
  logInfo(describeFamily(*e) + " ended (" + reason + ")");
  emit_("device-removed", e->toJson());
  removed(name);
}

void DeviceManager::scheduleRetry(const std::string& name) {
  DeviceEntry* e = devices_.find(name);
  if (!e) return;
  Retry& r = retries_[name];
  r.token = next_token_++;
  const uint64_t token = r.token;
  auto timer = loop_.addTimer(retryDelay(e->retries), false, [this, name, token] {
    if (auto it = retries_.find(name); it != retries_.end() && it->second.token == token) {
      it->second.timer = -1;  // fired: the loop dropped it
    }
    retry(name, token);
  });
  if (timer) {
    r.timer = *timer;
  } else {
    warn_("device '" + name + "' will not be reopened: " + timer.error().message);
  }
}

void DeviceManager::retry(const std::string& name, uint64_t token) {
  DeviceEntry* e = devices_.find(name);
  auto it = retries_.find(name);
  if (!e || !e->lost || it == retries_.end() || it->second.token != token) return;
  if (it->second.timer >= 0) loop_.removeTimer(it->second.timer);
  it->second.timer = -1;
  it->second.token = next_token_++;  // an earlier attempt still running is ignored
  const uint64_t attempt = it->second.token;
  opener_->submit([this, name, attempt, desc = e->description, driver = e->driver,
                   options = e->options]() mutable -> WorkerPool::Completion {
    // The driver that served it before, by name: a reopen must not switch drivers.
    auto fresh = std::make_shared<DeviceEntry>(
        DeviceSet::prepare(registry_, std::move(desc), driver, options));
    return guarded([this, name, attempt, fresh] { finishRetry(name, attempt, std::move(*fresh)); });
  });
}

void DeviceManager::finishRetry(const std::string& name, uint64_t token, DeviceEntry fresh) {
  DeviceEntry* e = devices_.find(name);
  auto it = retries_.find(name);
  if (!e || !e->lost || it == retries_.end() || it->second.token != token) {
    retire(fresh.device.share());  // a stale attempt that opened after all
    fresh.device.reset();
    return;
  }
  if (!fresh.usable()) {
    ++e->retries;
    e->error = "lost: " + fresh.error;
    logDebug("device '" + name + "' still gone (attempt " + std::to_string(e->retries) +
             "): " + fresh.error);
    scheduleRetry(name);
    return;
  }
  retries_.erase(it);
  e->device = std::move(fresh.device);
  e->lost = false;
  e->retries = 0;
  e->error.clear();
  logInfo(describeFamily(*e) + " is back");
  watchFd(*e);
  emit_("device-added", e->toJson());
  added(name);
}

void DeviceManager::cancelRetry(const std::string& name) {
  auto it = retries_.find(name);
  if (it == retries_.end()) return;
  if (it->second.timer >= 0) loop_.removeTimer(it->second.timer);
  retries_.erase(it);
}

// --- device fds and reads ---

void DeviceManager::watchFd(const DeviceEntry& e) {
  // Outputs have no read operation in the ABI: their fds stay with the driver.
  if (!e.usable() || e.description.family == PROCAM_FAMILY_OUTPUT) return;
  const int fd = e.device.pollFd();
  // A device being read is watched again when its result is back.
  if (fd < 0 || watched_.count(e.name) || reading_.count(e.name)) return;
  const std::string name = e.name;
  if (auto ok = loop_.add(fd, EPOLLIN, [this, name](uint32_t) { readEntry(name); }); !ok) {
    warn_("device '" + name + "': cannot watch its fd: " + ok.error().message);
    return;
  }
  watched_[name] = fd;
}

void DeviceManager::unwatchFd(const std::string& name) {
  auto it = watched_.find(name);
  if (it == watched_.end()) return;
  loop_.remove(it->second);  // before the device closes the fd
  watched_.erase(it);
}

void DeviceManager::sync() {
  for (auto it = watched_.begin(); it != watched_.end();) {
    const DeviceEntry* e = devices_.find(it->first);
    if (e && e->usable() && e->device.pollFd() == it->second) {
      ++it;
    } else {
      loop_.remove(it->second);
      it = watched_.erase(it);
    }
  }
  for (auto it = retries_.begin(); it != retries_.end();) {
    const DeviceEntry* e = devices_.find(it->first);
    if (e && e->lost) {
      ++it;
      continue;
    }
    if (it->second.timer >= 0) loop_.removeTimer(it->second.timer);
    it = retries_.erase(it);
  }
  for (const auto& e : devices_.entries()) watchFd(e);
}

bool DeviceManager::read(const std::string& name) {
  return readEntry(name);
}

bool DeviceManager::readEntry(const std::string& name) {
  DeviceEntry* e = devices_.find(name);
  if (!e || !e->usable()) {
    unwatchFd(name);
    return false;
  }
  if (!gateOpen(name)) {
    if (watched_.count(name)) gated_.insert(name);
    unwatchFd(name);
    return false;
  }
  switch (e->description.family) {
    case PROCAM_FAMILY_OUTPUT:
      return false;
    case PROCAM_FAMILY_TILT:
      return deliver(name, readOnce(e->device.raw(), PROCAM_FAMILY_TILT));
    case PROCAM_FAMILY_TRACKER:
    case PROCAM_FAMILY_CAMERA:
      if (reading_.count(name)) return false;  // one read per device at a time
      startRead(*e);
      return true;
  }
  return false;
}

DeviceManager::ReadResult DeviceManager::checkOnce(const procam_device& raw) {
  ReadResult r;
  std::array<char, 512> err{};
  r.rc = raw.ops.camera->check(raw.self, err.data(), err.size() - 1);
  if (r.rc != PROCAM_OK) {
    r.reason = err[0] ? err.data() : "liveness check failed (code " + std::to_string(r.rc) + ")";
  }
  return r;
}

void DeviceManager::checkCamera(const std::string& name) {
  DeviceEntry* e = devices_.find(name);
  if (!e || !e->usable() || reading_.count(name) || !gateOpen(name)) return;
  const procam_device& raw = e->device.raw();
  if (raw.ops.camera && raw.ops.camera->check) {
    startRead(*e, true);
  } else {
    readEntry(name);
  }
}

void DeviceManager::startRead(DeviceEntry& e, bool check_only) {
  const std::string name = e.name;
  auto ticket = std::make_shared<ReadTicket>();
  reading_[name] = ticket;
  unwatchFd(name);
  // The worker's share keeps the device alive if the loop closes it meanwhile.
  reader_->submit([this, name, ticket, device = e.device.share(), family = e.description.family,
                   check_only]() -> WorkerPool::Completion {
    auto result = std::make_shared<ReadResult>();
    if (ticket->begin()) {
      *result = check_only ? checkOnce(device->raw()) : readOnce(device->raw(), family);
      ticket->end();
    } else {
      result->withdrawn = true;
    }
    return guarded([this, name, ticket, device, result, check_only]() mutable {
      // A passed check carries no reading: nothing to deliver.
      if (check_only && result->rc == PROCAM_OK) result->withdrawn = true;
      finishRead(name, ticket, device, *result);
      // Closed meanwhile (lost, unplugged), this may be the last reference.
      retire(std::move(device));
    });
  });
}

void DeviceManager::retire(std::shared_ptr<plugins::Device> device) {
  if (!device) return;
  closer_->submit([device = std::move(device)]() mutable -> WorkerPool::Completion {
    device.reset();
    return {};
  });
}

void DeviceManager::finishRead(const std::string& name, const std::shared_ptr<ReadTicket>& ticket,
                               const std::shared_ptr<plugins::Device>& device,
                               const ReadResult& result) {
  if (auto it = reading_.find(name); it != reading_.end() && it->second == ticket) {
    reading_.erase(it);
  }
  DeviceEntry* e = devices_.find(name);
  if (!e || !e->usable()) return;
  // Re-armed, also when the entry holds a device reopened meanwhile.
  if (gateOpen(name)) {
    watchFd(*e);
  } else if (e->device.pollFd() >= 0) {
    gated_.insert(name);  // the presence check watches it again when the gate opens
  }
  // A reading of a device closed or reopened while it was read is dropped:
  // the set no longer holds that device (a loss was reported when noticed).
  if (result.withdrawn || e->device.share() != device) return;
  deliver(name, result);
}

bool DeviceManager::deliver(const std::string& name, const ReadResult& result) {
  if (result.rc != PROCAM_OK) {
    report(name, result.rc, result.reason);
    return false;
  }
  const DeviceEntry* e = devices_.find(name);
  if (!e) return false;
  if (std::holds_alternative<CameraFrame>(result.reading)) {
    last_frame_[name] = std::chrono::steady_clock::now();
  }
  // Hooks may change the set: hand them a copy of the list and look nothing up after.
  const auto hooks = on_reading_;
  for (const auto& h : hooks) h(*e, result.reading);
  return true;
}

ReadFence DeviceManager::readFence(const std::vector<std::string>& names) {
  std::vector<std::shared_ptr<ReadTicket>> tickets;
  for (const auto& n : names) {
    if (auto it = reading_.find(n); it != reading_.end()) {
      it->second->withdraw();
      tickets.push_back(it->second);
    }
  }
  return ReadFence(std::move(tickets));
}

Result<int> DeviceManager::pollEvery(const std::string& name, std::chrono::nanoseconds interval) {
  if (!devices_.find(name)) return fail(ErrorCode::kNotFound, "no device '" + name + "'");
  auto id = loop_.addTimer(interval, true, [this, name] { readEntry(name); });
  if (id) polls_[*id] = name;
  return id;
}

void DeviceManager::stopPolling(int id) {
  if (polls_.erase(id) > 0) loop_.removeTimer(id);
}

void DeviceManager::presenceCheck() {
  for (auto it = gated_.begin(); it != gated_.end();) {
    const DeviceEntry* e = devices_.find(*it);
    if (e && !gateOpen(*it)) {
      ++it;
      continue;
    }
    if (e) watchFd(*e);
    it = gated_.erase(it);
  }
  std::vector<std::string> names;
  for (const auto& e : devices_.entries()) {
    const auto family = e.description.family;
    if (!e.usable() || family == PROCAM_FAMILY_OUTPUT || family == PROCAM_FAMILY_CAMERA ||
        watched_.count(e.name) || gated_.count(e.name) || reading_.count(e.name)) {
      continue;
    }
    bool polled = false;
    for (const auto& [id, n] : polls_) polled = polled || n == e.name;
    if (!polled) names.push_back(e.name);
  }
  for (const auto& n : names) readEntry(n);
  // A capture is the only call every camera driver answers with PROCAM_ENODEV
  // once the camera is gone (a format is answered from memory). A camera that
  // delivers frames anyway needs no extra one.
  for (const auto& n : silentCameras()) checkCamera(n);
}

std::vector<std::string> DeviceManager::silentCameras() const {
  const auto now = std::chrono::steady_clock::now();
  // Half the interval: a camera captured by the previous check delivered its
  // frame just under one interval ago and is due again now.
  const auto recent = presence_interval_ / 2;
  std::vector<std::string> due;
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_CAMERA || !e.usable() || gated_.count(e.name) ||
        reading_.count(e.name) || !gateOpen(e.name)) {
      continue;
    }
    if (auto it = last_frame_.find(e.name); it != last_frame_.end() && now - it->second < recent) {
      continue;
    }
    due.push_back(e.name);
  }
  return due;
}

void DeviceManager::added(const std::string& name) {
  const auto hooks = on_added_;
  for (const auto& h : hooks) {
    if (const DeviceEntry* e = devices_.find(name)) h(*e);
  }
}

void DeviceManager::removed(const std::string& name) {
  const auto hooks = on_removed_;
  for (const auto& h : hooks) {
    if (const DeviceEntry* e = devices_.find(name)) h(*e);
  }
}

}  // namespace procam::daemon
