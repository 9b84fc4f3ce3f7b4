#pragma once
// PROCAM_SIM_UNPLUG=name@T1-T2[,name@T1-T2...]: the mock device `name`
// behaves as unplugged (every operation and create() return PROCAM_ENODEV)
// from T1 to T2 seconds after the process started, so that tests can show a
// device being lost and coming back.
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"

namespace procam::sim::mock {

struct UnplugWindow {
  std::string device;
  double from_s = 0, to_s = 0;
};

inline constexpr const char* kUnplugVariable = "PROCAM_SIM_UNPLUG";

Result<std::vector<UnplugWindow>> parseUnplugWindows(std::string_view text);
// Whether `device` is unplugged `t` seconds after start under `windows`.
bool unpluggedAt(const std::vector<UnplugWindow>& windows, std::string_view device, double t);

// From the environment, at the current time; a malformed variable is kInvalidInput.
Result<bool> unpluggedNow(std::string_view device);

}  // namespace procam::sim::mock
