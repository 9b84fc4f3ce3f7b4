#include "tilt/i2c/i2c_chips.hpp"

namespace procam::tilt {

std::uint16_t defaultAddress(I2cChip chip) {
  switch (chip) {
    case I2cChip::kAdxl345:
      return 0x53;
    case I2cChip::kMpu6050:
      return 0x68;
    case I2cChip::kLis3dh:
      return 0x18;
  }
  return 0;
}

Result<I2cChip> parseI2cChip(const std::string& name) {
  if (name == "adxl345") return I2cChip::kAdxl345;
  if (name == "mpu6050") return I2cChip::kMpu6050;
  if (name == "lis3dh") return I2cChip::kLis3dh;
  return fail(ErrorCode::kNotFound, "unknown i2c accelerometer '" + name + "'");
}

std::unique_ptr<I2cAccelerometer> makeI2cAccelerometer(I2cChip chip, std::shared_ptr<I2cBus> bus,
                                                       std::uint16_t address,
                                                       const I2cAccelConfig& config) {
  switch (chip) {
    case I2cChip::kAdxl345:
      return makeAdxl345(std::move(bus), address, config);
    case I2cChip::kMpu6050:
      return makeMpu6050(std::move(bus), address, config);
    case I2cChip::kLis3dh:
      return makeLis3dh(std::move(bus), address, config);
  }
  return nullptr;
}

}  // namespace procam::tilt
