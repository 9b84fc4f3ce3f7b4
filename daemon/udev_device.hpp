#pragma once
// What procamd takes from a udev device, and how such a device becomes a
// driver's device description. Pure: no libudev here (see udev_monitor.hpp),
// so the conversion is testable from plain values.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "driver.hpp"

namespace procam::daemon {

// A udev device as enumerated or received from the monitor.
struct UdevRecord {
  std::string action;  // "add", "remove", "change", ...; empty when enumerated
  std::string subsystem;
  std::string devnode;
  std::string syspath;
  std::string sysname;
  std::vector<std::pair<std::string, std::string>> properties;

  std::string property(std::string_view key) const;
};

// The subsystems in which udev/70-procamd.rules gives devices a device role
// (camera, tilt, tracker, output); enumeration and the monitor look only here.
std::span<const char* const> procamSubsystems();

// PROCAM_ROLE -> family; nullopt for the bus roles ("i2c-adapter",
// "gpiochip": buses a configured sensor hangs off, not devices) and others.
std::optional<procam_family> familyOfRole(std::string_view role);

// The description of a device the rules classified, named after its sysname
// ("video0", "iio:device0", "card0"); nullopt when the device has no device
// role, i.e. is not procamd's.
std::optional<plugins::DeviceDescription> describeUdevDevice(const UdevRecord& record);

}  // namespace procam::daemon
