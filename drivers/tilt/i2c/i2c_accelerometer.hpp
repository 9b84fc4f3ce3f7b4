#pragma once
// Register-level accelerometers on I2C (ADXL345, MPU-6050, LIS3DH). The common part:
// identity probe, range/rate setup, data-ready polling, burst read of the three axes,
// conversion to m/s^2. Each chip supplies its registers, byte order and scale.
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "tilt/i2c/i2c_bus.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::tilt {

struct I2cAccelConfig {
  double range_g = 2;    // smallest supported full scale >= this
  double rate_hz = 100;  // smallest supported output rate >= this
  int max_polls = 50;    // data-ready polls per read() before kNotFound
  std::chrono::microseconds poll_interval{500};
};

class I2cAccelerometer : public TiltSensor {
 public:
  I2cAccelerometer(std::shared_ptr<I2cBus> bus, std::uint16_t address, I2cAccelConfig config)
      : bus_(std::move(bus)), address_(address), config_(config) {}
  ~I2cAccelerometer() override = default;  // derived classes call close()

  Result<void> open() override;
  Result<TiltSample> read() override;
  void close() override;

  double gPerCount() const { return g_per_count_; }
  double rangeG() const { return range_g_; }
  double rateHz() const { return rate_hz_; }

 protected:
  struct Setup {
    double g_per_count, range_g, rate_hz;
  };
  virtual Result<void> probe() = 0;       // identity register check
  virtual Result<Setup> configure() = 0;  // range, rate, measurement mode
  virtual Result<bool> dataReady() = 0;
  virtual Result<std::array<std::int16_t, 3>> readCounts() = 0;
  // The package's gyroscope read by the last readCounts() (rad/s, chip axes); nullopt
  // for a chip without one.
  virtual std::optional<Vec3> lastRate() const { return std::nullopt; }
  virtual Result<void> standby() = 0;

  Result<std::uint8_t> readRegister(std::uint8_t reg);
  Result<void> writeRegister(std::uint8_t reg, std::uint8_t value);
  Result<void> readBlock(std::uint8_t first_reg, std::span<std::uint8_t> out);
  Result<void> expectIdentity(std::uint8_t reg, std::uint8_t expected, const char* chip);
  const I2cAccelConfig& config() const { return config_; }

 private:
  std::shared_ptr<I2cBus> bus_;
  std::uint16_t address_;
  I2cAccelConfig config_;
  bool open_ = false;
  double g_per_count_ = 0, range_g_ = 0, rate_hz_ = 0;
};

enum class I2cChip { kAdxl345, kMpu6050, kLis3dh };

// Default 7-bit addresses: ADXL345 0x53, MPU-6050 0x68, LIS3DH 0x18.
std::uint16_t defaultAddress(I2cChip chip);
Result<I2cChip> parseI2cChip(const std::string& name);  // "adxl345", "mpu6050", "lis3dh"

std::unique_ptr<I2cAccelerometer> makeI2cAccelerometer(I2cChip chip, std::shared_ptr<I2cBus> bus,
                                                       std::uint16_t address,
                                                       const I2cAccelConfig& config = {});

// Little/big-endian two's complement 16-bit from two bytes.
inline std::int16_t le16(const std::uint8_t* p) {
  return std::int16_t(std::uint16_t(p[0] | (p[1] << 8)));
}
inline std::int16_t be16(const std::uint8_t* p) {
  return std::int16_t(std::uint16_t((p[0] << 8) | p[1]));
}

}  // namespace procam::tilt
