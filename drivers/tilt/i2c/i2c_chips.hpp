#pragma once
// Constructors of the chip drivers (one .cpp per chip, datasheet register maps).
#include <memory>

#include "tilt/i2c/i2c_accelerometer.hpp"

namespace procam::tilt {

std::unique_ptr<I2cAccelerometer> makeAdxl345(std::shared_ptr<I2cBus> bus, std::uint16_t address,
                                              const I2cAccelConfig& config);
std::unique_ptr<I2cAccelerometer> makeMpu6050(std::shared_ptr<I2cBus> bus, std::uint16_t address,
                                              const I2cAccelConfig& config);
std::unique_ptr<I2cAccelerometer> makeLis3dh(std::shared_ptr<I2cBus> bus, std::uint16_t address,
                                             const I2cAccelConfig& config);

}  // namespace procam::tilt
