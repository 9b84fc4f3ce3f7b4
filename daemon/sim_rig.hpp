#pragma once
// The devices of a virtual-rig scene, as descriptions the mock drivers accept
// (subsystem "sim", properties SIM_SCENE and SIM_DEVICE).
#include <string>
#include <vector>

#include "core/error.hpp"
#include "driver.hpp"

namespace procam::daemon {

inline constexpr const char* kDefaultSimScene = "handheld";

// kNotFound (listing the shipped scenes) when the scene does not exist;
// kIo when this procamd was built without the virtual rig.
Result<std::vector<plugins::DeviceDescription>> simDevices(const std::string& scene);

}  // namespace procam::daemon
