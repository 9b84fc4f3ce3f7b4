#pragma once
// The set of drivers the daemon knows, and matching a device to the driver
// that scores best for it.
#include <optional>
#include <string>
#include <vector>

#include "driver.hpp"

namespace procam::plugins {

struct Match {
  Driver driver;
  int score = 0;
};

class DriverRegistry {
 public:
  // A driver with the same family and name as an existing one is refused
  // (returns false) so that a plugin cannot silently replace another.
  bool add(const Driver& driver);
  void addAll(const std::vector<Driver>& drivers, std::vector<std::string>& out_refused);

  const std::vector<Driver>& drivers() const { return drivers_; }
  std::optional<Driver> find(procam_family family, const std::string& name) const;

  // The driver of the description's family with the highest probe() score;
  // none when every driver scores 0 or less. Ties go to the earlier driver.
  std::optional<Match> bestMatch(DeviceDescription& desc) const;

 private:
  std::vector<Driver> drivers_;
};

}  // namespace procam::plugins
