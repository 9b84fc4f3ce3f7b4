#pragma once
// The devices the daemon has opened: one entry per configured or discovered
// device, with the driver that serves it and, when opening failed or the
// device went away, why.
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "driver.hpp"
#include "registry.hpp"

namespace procam::daemon {

// A created device with shared ownership: the set holds one reference, and a
// worker that uses the device holds another (share()) for as long as it runs,
// so closing an entry on the loop never destroys a device under a worker.
class DeviceHandle {
 public:
  DeviceHandle() = default;
  DeviceHandle(plugins::Device device)  // NOLINT: a created device converts implicitly
      : device_(std::make_shared<plugins::Device>(std::move(device))) {}

  bool valid() const { return device_ && device_->valid(); }
  // The C device; all null when not valid().
  const procam_device& raw() const;
  int pollFd() const { return valid() ? device_->pollFd() : -1; }
  std::shared_ptr<plugins::Device> share() const { return device_; }
  // Drops this reference; the driver's destroy runs when the last one goes.
  void reset() { device_.reset(); }

 private:
  std::shared_ptr<plugins::Device> device_;
};

using DeviceOptions = std::vector<std::pair<std::string, std::string>>;

// A status that closes the device: gone (PROCAM_ENODEV, reopened with
// back-off) or ended for good (PROCAM_EEND, a finished recording).
inline bool closesDevice(int rc) {
  return rc == PROCAM_ENODEV || rc == PROCAM_EEND;
}

struct DeviceEntry {
  std::string name;
  plugins::DeviceDescription description;
  std::string driver;  // empty when no driver matched
  std::string origin;  // where the driver came from
  int score = 0;       // the driver's probe() score (0: chosen by name)
  DeviceOptions options;
  DeviceHandle device;
  std::string error;   // non-empty: not usable
  bool lost = false;   // was open, then failed with PROCAM_ENODEV; retried
  bool ended = false;  // was open, then its stream ended (PROCAM_EEND); not retried
  int retries = 0;     // failed reopen attempts since it was lost

  bool usable() const { return device.valid(); }
  // "open", "error", "lost" or "ended".
  const char* state() const;
  nlohmann::json toJson() const;
};

class DeviceSet {
 public:
  // Matches and creates a device with the named driver (empty: the
  // best-scoring one) without adding it; safe on any thread as long as the
  // registry does not change. The entry carries the reason when it failed.
  static DeviceEntry prepare(const plugins::DriverRegistry& registry,
                             plugins::DeviceDescription desc, const std::string& driver_name,
                             const DeviceOptions& options);
  // Opens a device (prepare + add). The entry is kept even when opening
  // fails, with the reason.
  DeviceEntry& open(const plugins::DriverRegistry& registry, plugins::DeviceDescription desc,
                    const std::string& driver_name, const DeviceOptions& options);
  DeviceEntry& add(DeviceEntry entry);
  // Closes and forgets a device; false when unknown.
  bool close(const std::string& name);
  void closeAll();

  // References into the set stay valid until the next add or close.
  DeviceEntry* find(const std::string& name);
  DeviceEntry* findBySyspath(const std::string& syspath);
  DeviceEntry* findByDevnode(const std::string& devnode);

  const std::vector<DeviceEntry>& entries() const { return entries_; }
  std::vector<DeviceEntry>& entries() { return entries_; }
  // The first usable device of a family.
  DeviceEntry* firstUsable(procam_family family);
  size_t count(procam_family family) const;

 private:
  std::vector<DeviceEntry> entries_;
};

}  // namespace procam::daemon
