#include "udev_device.hpp"

#include <array>

namespace procam::daemon {

std::string UdevRecord::property(std::string_view key) const {
  for (const auto& [k, v] : properties) {
    if (k == key) return v;
  }
  return {};
}

std::span<const char* const> procamSubsystems() {
  static constexpr std::array<const char*, 4> kSubsystems{"video4linux", "iio", "hidraw", "drm"};
  return kSubsystems;
}

std::optional<procam_family> familyOfRole(std::string_view role) {
  for (procam_family f :
       {PROCAM_FAMILY_CAMERA, PROCAM_FAMILY_TILT, PROCAM_FAMILY_TRACKER, PROCAM_FAMILY_OUTPUT}) {
    if (role == plugins::familyName(f)) return f;
  }
  return std::nullopt;
}

std::optional<plugins::DeviceDescription> describeUdevDevice(const UdevRecord& record) {
  auto family = familyOfRole(record.property("PROCAM_ROLE"));
  if (!family) return std::nullopt;
  plugins::DeviceDescription d;
  d.family = *family;
  d.subsystem = record.subsystem;
  d.devnode = record.devnode;
  d.syspath = record.syspath;
  d.name = record.sysname;
  if (d.name.empty()) d.name = record.syspath.substr(record.syspath.find_last_of('/') + 1);
  d.properties = record.properties;
  return d;
}

}  // namespace procam::daemon
