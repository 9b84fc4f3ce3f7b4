#include "device_set.hpp"

#include <algorithm>

namespace procam::daemon {

const procam_device& DeviceHandle::raw() const {
  static const procam_device kNone{};
  return valid() ? device_->raw() : kNone;
}

const char* DeviceEntry::state() const {
  if (usable()) return "open";
  if (ended) return "ended";
  return lost ? "lost" : "error";
}

nlohmann::json DeviceEntry::toJson() const {
  nlohmann::json j = {{"name", name},
                      {"family", plugins::familyName(description.family)},
                      {"driver", driver.empty() ? nlohmann::json(nullptr) : nlohmann::json(driver)},
                      {"state", state()}};
  if (!description.subsystem.empty()) j["subsystem"] = description.subsystem;
  if (!description.devnode.empty()) j["devnode"] = description.devnode;
  if (!description.syspath.empty()) j["syspath"] = description.syspath;
  if (!origin.empty()) j["origin"] = origin;
  if (score > 0) j["score"] = score;
  if (!error.empty()) j["error"] = error;
  if (lost) j["retries"] = retries;
  return j;
}

DeviceEntry DeviceSet::prepare(const plugins::DriverRegistry& registry,
                               plugins::DeviceDescription desc, const std::string& driver_name,
                               const DeviceOptions& options) {
  DeviceEntry entry;
  entry.name = desc.name;
  entry.description = std::move(desc);
  entry.options = options;
  std::optional<plugins::Driver> driver;
  if (!driver_name.empty()) {
    driver = registry.find(entry.description.family, driver_name);
    if (!driver) {
      entry.error = std::string("no ") + plugins::familyName(entry.description.family) +
                    " driver named '" + driver_name + "' is built in or installed";
    }
  } else if (auto match = registry.bestMatch(entry.description)) {
    driver = match->driver;
    entry.score = match->score;
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
  return entry;
}

DeviceEntry& DeviceSet::open(const plugins::DriverRegistry& registry,
                             plugins::DeviceDescription desc, const std::string& driver_name,
                             const DeviceOptions& options) {
  return add(prepare(registry, std::move(desc), driver_name, options));
}

DeviceEntry& DeviceSet::add(DeviceEntry entry) {
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

namespace {

template <class Pred>
DeviceEntry* findIf(std::vector<DeviceEntry>& entries, Pred pred) {
  auto it = std::find_if(entries.begin(), entries.end(), pred);
  return it == entries.end() ? nullptr : &*it;
}

}  // namespace

DeviceEntry* DeviceSet::find(const std::string& name) {
  return findIf(entries_, [&](const DeviceEntry& e) { return e.name == name; });
}

DeviceEntry* DeviceSet::findBySyspath(const std::string& syspath) {
  if (syspath.empty()) return nullptr;
  return findIf(entries_, [&](const DeviceEntry& e) { return e.description.syspath == syspath; });
}

DeviceEntry* DeviceSet::findByDevnode(const std::string& devnode) {
  if (devnode.empty()) return nullptr;
  return findIf(entries_, [&](const DeviceEntry& e) { return e.description.devnode == devnode; });
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
