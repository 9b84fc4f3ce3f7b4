#include "registry.hpp"

namespace procam::plugins {

bool DriverRegistry::add(const Driver& driver) {
  if (find(driver.family(), driver.name())) return false;
  drivers_.push_back(driver);
  return true;
}

void DriverRegistry::addAll(const std::vector<Driver>& drivers,
                            std::vector<std::string>& out_refused) {
  for (const Driver& d : drivers) {
    if (!add(d)) {
      out_refused.push_back(std::string(familyName(d.family())) + " driver '" + d.name() +
                            "' from " + d.origin + " duplicates an existing driver");
    }
  }
}

std::optional<Driver> DriverRegistry::find(procam_family family, const std::string& name) const {
  for (const Driver& d : drivers_) {
    if (d.family() == family && d.name() == name) return d;
  }
  return std::nullopt;
}

std::optional<Match> DriverRegistry::bestMatch(DeviceDescription& desc) const {
  std::optional<Match> best;
  const procam_device_desc& view = desc.view();
  for (const Driver& d : drivers_) {
    if (d.family() != desc.family) continue;
    const int score = d.factory->probe(&view);
    if (score > 0 && (!best || score > best->score)) best = Match{d, score};
  }
  return best;
}

}  // namespace procam::plugins
