#pragma once
// /dev/i2c-N through ioctl(I2C_RDWR). The file descriptor is owned (closed on
// destruction).
#include <string>

#include "tilt/i2c/i2c_bus.hpp"

namespace procam::tilt {

class I2cDevBus final : public I2cBus {
 public:
  // kIo (with errno text) when the node cannot be opened.
  static Result<I2cDevBus> open(const std::string& path);

  I2cDevBus(I2cDevBus&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) {
    other.fd_ = -1;
  }
  I2cDevBus& operator=(I2cDevBus&& other) noexcept;
  I2cDevBus(const I2cDevBus&) = delete;
  I2cDevBus& operator=(const I2cDevBus&) = delete;
  ~I2cDevBus() override;

  Result<void> transfer(std::uint16_t address, std::span<const std::uint8_t> write,
                        std::span<std::uint8_t> read) override;

 private:
  I2cDevBus(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_ = -1;
  std::string path_;
};

}  // namespace procam::tilt
