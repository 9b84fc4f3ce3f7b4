#pragma once
// The transport of the register-level drivers: one combined I2C transaction (write the
// register address and data, then, after a repeated start, read), as I2C_RDWR does.
// Tests substitute simulated chips; I2cDevBus is the kernel's /dev/i2c-N.
#include <cstdint>
#include <span>

#include "core/error.hpp"

namespace procam::tilt {

class I2cBus {
 public:
  virtual ~I2cBus() = default;
  // kNotFound when the address is not acknowledged (NACK), kIo for other bus
  // failures (timeout, stuck or lost arbitration). `read` may be empty.
  virtual Result<void> transfer(std::uint16_t address, std::span<const std::uint8_t> write,
                                std::span<std::uint8_t> read) = 0;
};

}  // namespace procam::tilt
