#pragma once
// libudev behind RAII handles: the context, enumeration of procamd's
// subsystems, and the netlink monitor whose fd the event loop watches.
#include <memory>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "udev_device.hpp"

struct udev;
struct udev_device;
struct udev_monitor;

namespace procam::daemon {

// Copies what procamd needs out of a libudev device.
UdevRecord udevRecordOf(udev_device* device);

class Udev {
 public:
  static Result<Udev> create();
  // Every device of procamSubsystems(), in the order udev lists them.
  Result<std::vector<UdevRecord>> enumerate() const;
  udev* get() const { return udev_.get(); }

 private:
  struct Unref {
    void operator()(udev* u) const;
  };
  std::unique_ptr<udev, Unref> udev_;
};

class UdevMonitor {
 public:
  // Listens to udev's (not the kernel's) events of procamSubsystems().
  static Result<UdevMonitor> create(const Udev& udev);
  int fd() const;
  // The next queued event; nullopt when none is pending (non-blocking).
  std::optional<UdevRecord> receive();

 private:
  struct Unref {
    void operator()(udev_monitor* m) const;
  };
  std::unique_ptr<udev_monitor, Unref> monitor_;
};

}  // namespace procam::daemon
