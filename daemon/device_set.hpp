#pragma once
// The devices the daemon has opened: one entry per configured or discovered
// device, with the driver that serves it and, when opening failed, why.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "driver.hpp"
#include "registry.hpp"

namespace procam::daemon {

struct DeviceEntry {
  std::string name;
  plugins::DeviceDescription description;
  std::string driver;  // empty when no driver matched
  std::string origin;  // where the driver came from
  plugins::Device device;
  std::string error;  // non-empty: not usable

  bool usable() const { return device.valid(); }
  nlohmann::json toJson() const;
};

class DeviceSet {
 public:
  // Opens a device with the named driver (empty: the best-scoring one).
  // The entry is kept even when opening fails, with the reason.
  DeviceEntry& open(const plugins::DriverRegistry& registry, plugins::DeviceDescription desc,
                    const std::string& driver_name,
                    const std::vector<std::pair<std::string, std::string>>& options);
  // Closes and forgets a device; false when unknown.
  bool close(const std::string& name);
  void closeAll();

  const std::vector<DeviceEntry>& entries() const { return entries_; }
  std::vector<DeviceEntry>& entries() { return entries_; }
  // The first usable device of a family.
  DeviceEntry* firstUsable(procam_family family);
  size_t count(procam_family family) const;

 private:
  std::vector<DeviceEntry> entries_;
};

}  // namespace procam::daemon
