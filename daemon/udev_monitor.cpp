#include "udev_monitor.hpp"

#include <libudev.h>

#include <cerrno>
#include <cstring>

namespace procam::daemon {

namespace {

std::string text(const char* s) {
  return s ? std::string(s) : std::string();
}

struct DeviceUnref {
  void operator()(udev_device* d) const { udev_device_unref(d); }
};
using DevicePtr = std::unique_ptr<udev_device, DeviceUnref>;

struct EnumerateUnref {
  void operator()(udev_enumerate* e) const { udev_enumerate_unref(e); }
};

Error udevError(const std::string& what, int rc) {
  return Error{ErrorCode::kIo, what + ": " + std::strerror(rc < 0 ? -rc : errno)};
}

}  // namespace

UdevRecord udevRecordOf(udev_device* device) {
  UdevRecord r;
  r.action = text(udev_device_get_action(device));
  r.subsystem = text(udev_device_get_subsystem(device));
  r.devnode = text(udev_device_get_devnode(device));
  r.syspath = text(udev_device_get_syspath(device));
  r.sysname = text(udev_device_get_sysname(device));
  udev_list_entry* e = nullptr;
  udev_list_entry_foreach(e, udev_device_get_properties_list_entry(device)) {
    r.properties.emplace_back(text(udev_list_entry_get_name(e)),
                              text(udev_list_entry_get_value(e)));
  }
  return r;
}

void Udev::Unref::operator()(udev* u) const {
  udev_unref(u);
}

Result<Udev> Udev::create() {
  Udev u;
  u.udev_.reset(udev_new());
  if (!u.udev_) return tl::unexpected(udevError("udev_new", 0));
  return u;
}

Result<std::vector<UdevRecord>> Udev::enumerate() const {
  std::unique_ptr<udev_enumerate, EnumerateUnref> e(udev_enumerate_new(udev_.get()));
  if (!e) return tl::unexpected(udevError("udev_enumerate_new", 0));
  for (const char* subsystem : procamSubsystems()) {
    if (int rc = udev_enumerate_add_match_subsystem(e.get(), subsystem); rc < 0) {
      return tl::unexpected(udevError("udev enumeration filter", rc));
    }
  }
  if (int rc = udev_enumerate_scan_devices(e.get()); rc < 0) {
    return tl::unexpected(udevError("udev enumeration", rc));
  }
  std::vector<UdevRecord> out;
  udev_list_entry* entry = nullptr;
  udev_list_entry_foreach(entry, udev_enumerate_get_list_entry(e.get())) {
    // A device may vanish between the scan and this lookup; skip it.
    DevicePtr d(udev_device_new_from_syspath(udev_.get(), udev_list_entry_get_name(entry)));
    if (d) out.push_back(udevRecordOf(d.get()));
  }
  return out;
}

void UdevMonitor::Unref::operator()(udev_monitor* m) const {
  udev_monitor_unref(m);
}

Result<UdevMonitor> UdevMonitor::create(const Udev& udev) {
  UdevMonitor m;
  m.monitor_.reset(udev_monitor_new_from_netlink(udev.get(), "udev"));
  if (!m.monitor_) return tl::unexpected(udevError("udev monitor", 0));
  for (const char* subsystem : procamSubsystems()) {
    if (int rc =
            udev_monitor_filter_add_match_subsystem_devtype(m.monitor_.get(), subsystem, nullptr);
        rc < 0) {
      return tl::unexpected(udevError("udev monitor filter", rc));
    }
  }
  if (int rc = udev_monitor_enable_receiving(m.monitor_.get()); rc < 0) {
    return tl::unexpected(udevError("udev monitor", rc));
  }
  return m;
}

int UdevMonitor::fd() const {
  return udev_monitor_get_fd(monitor_.get());
}

std::optional<UdevRecord> UdevMonitor::receive() {
  // The monitor's socket is non-blocking: null when nothing is queued.
  DevicePtr d(udev_monitor_receive_device(monitor_.get()));
  if (!d) return std::nullopt;
  return udevRecordOf(d.get());
}

}  // namespace procam::daemon
