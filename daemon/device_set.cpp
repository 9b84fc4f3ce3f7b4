#include "device_set.hpp"

#include <algorithm>

namespace procam::daemon {

nlohmann::json DeviceEntry::toJson() const {
  nlohmann::json j = {{"name", name},
                      {"family", plugins::familyName(description.family)},
                      {"driver", driver.empty() ? nlohmann::json(nullptr) : nlohmann::json(driver)},
                      {"state", usable() ? "open" : "error"}};
  if (!description.devnode.empty()) j["devnode"] = description.devnode;
  if (!origin.empty()) j["origin"] = origin;
  if (!error.empty()) j["error"] = error;
  return j;
}

DeviceEntry& DeviceSet::open(const plugins::DriverRegistry& registry,
                             plugins::DeviceDescription desc, const std::string& driver_name,
                             const std::vector<std::pair<std::string, std::string>>& options) {
  DeviceEntry entry;
  entry.name = desc.name;
  entry.description = std::move(desc);
  std::optional<plugins::Driver> driver;
  if (!driver_name.empty()) {
    driver = registry.find(entry.description.family, driver_name);
    if (!driver) {
      entry.error = std::string("no ") + plugins::familyName(entry.description.family) +
                    " driver named '" + driver_name + "' is built in or installed";
    }
  } else if (auto match = registry.bestMatch(entry.description)) {
    driver = match->driver;
  } else {
    entry.error = std::string("no ") + plugins::familyName(entry.description.family) +
                  " driver accepts this device";
  }
  if (driver) {
    entry.driver = driver->name();
    entry.origin = driver->origin;
    auto device = plugins::createDevice(*driver, entry.description, options);
    if (device) {
      entry.device = std::move(*device);
    } else {
      entry.error = device.error().message;
    }
  }
  entries_.push_back(std::move(entry));
  return entries_.back();
}

bool DeviceSet::close(const std::string& name) {
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const DeviceEntry& e) { return e.name == name; });
  if (it == entries_.end()) return false;
  entries_.erase(it);
  return true;
}

void DeviceSet::closeAll() {
  entries_.clear();
}

DeviceEntry* DeviceSet::firstUsable(procam_family family) {
  for (auto& e : entries_) {
    if (e.description.family == family && e.usable()) return &e;
  }
  return nullptr;
}

size_t DeviceSet::count(procam_family family) const {
  return static_cast<size_t>(std::count_if(entries_.begin(), entries_.end(), [&](const auto& e) {
    return e.description.family == family;
  }));
}

}  // namespace procam::daemon
