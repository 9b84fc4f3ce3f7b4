#include "tilt/i2c/i2c_dev_bus.hpp"

#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

namespace procam::tilt {

Result<I2cDevBus> I2cDevBus::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
  return I2cDevBus(fd, path);
}

I2cDevBus& I2cDevBus::operator=(I2cDevBus&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

I2cDevBus::~I2cDevBus() {
  if (fd_ >= 0) ::close(fd_);
}

Result<void> I2cDevBus::transfer(std::uint16_t address, std::span<const std::uint8_t> write,
                                 std::span<std::uint8_t> read) {
  if (fd_ < 0) return fail(ErrorCode::kIo, "i2c bus is closed");
  std::vector<std::uint8_t> out(write.begin(), write.end());
  i2c_msg msgs[2]{};
  unsigned n = 0;
  if (!out.empty()) msgs[n++] = {address, 0, std::uint16_t(out.size()), out.data()};
  if (!read.empty()) msgs[n++] = {address, I2C_M_RD, std::uint16_t(read.size()), read.data()};
  if (n == 0) return {};
  i2c_rdwr_ioctl_data data{msgs, n};
  if (ioctl(fd_, I2C_RDWR, &data) >= 0) return {};
  const int err = errno;
  char addr[8];
  std::snprintf(addr, sizeof addr, "0x%02x", address);
  if (err == ENXIO || err == EREMOTEIO)
    return fail(ErrorCode::kNotFound, path_ + ": no acknowledge from " + addr);
  return fail(ErrorCode::kIo, path_ + ": transfer to " + addr + " failed: " + std::strerror(err));
}

}  // namespace procam::tilt
