// InvenSense MPU-6050 (register map rev. 4.2): WHO_AM_I 0x75 = 0x68; PWR_MGMT_1 0x6B
// (0x01: awake, PLL on gyro X; 0x40 sleep); CONFIG 0x1A (DLPF_CFG 3 -> 1 kHz internal
// rate); SMPLRT_DIV 0x19 (rate = 1 kHz / (1 + div)); ACCEL_CONFIG 0x1C (AFS_SEL bits
// 4:3, 16384 LSB/g at ±2 g, halving per step); INT_ENABLE 0x38 (bit 0 DATA_RDY_EN);
// INT_STATUS 0x3A (bit 0 DATA_RDY_INT); ACCEL_XOUT_H..ACCEL_ZOUT_L 0x3B..0x40 big-endian;
// the gyroscope: GYRO_CONFIG 0x1B (FS_SEL bits 4:3, 131 LSB/(deg/s) at +-250 deg/s,
// halving per step), GYRO_XOUT_H..GYRO_ZOUT_L 0x43..0x48 big-endian on the
// accelerometer's axes, after TEMP_OUT 0x41..0x42: one burst of 14 bytes from 0x3B
// reads both from the same sample.
#include <algorithm>
#include <cmath>

#include "tilt/i2c/i2c_chips.hpp"

namespace procam::tilt {
namespace {

class Mpu6050 final : public I2cAccelerometer {
 public:
  using I2cAccelerometer::I2cAccelerometer;
  ~Mpu6050() override { close(); }
  std::string name() const override { return "mpu6050"; }

 private:
  Result<void> probe() override { return expectIdentity(0x75, 0x68, "MPU-6050"); }

  Result<Setup> configure() override {
    int afs = 0;
    while (afs < 3 && (2 << afs) < config().range_g) ++afs;
    const int div = std::clamp(int(std::floor(1000.0 / config().rate_hz)) - 1, 0, 255);
    const std::pair<std::uint8_t, std::uint8_t> writes[] = {{0x6B, 0x01},
                                                            {0x1A, 0x03},
                                                            {0x19, std::uint8_t(div)},
                                                            {0x1C, std::uint8_t(afs << 3)},
                                                            {0x1B, std::uint8_t(kGyroFsSel << 3)},
                                                            {0x38, 0x01}};
    for (auto [reg, value] : writes)
      if (auto r = writeRegister(reg, value); !r) return tl::unexpected(r.error());
    return Setup{double(1 << afs) / 16384.0, double(2 << afs), 1000.0 / (1 + div)};
  }

  Result<bool> dataReady() override {
    auto v = readRegister(0x3A);
    if (!v) return tl::unexpected(v.error());
    return (*v & 0x01) != 0;
  }

  Result<std::array<std::int16_t, 3>> readCounts() override {
    std::uint8_t b[14];
    if (auto r = readBlock(0x3B, b); !r) return tl::unexpected(r.error());
    // +-500 deg/s (a hand turns a projector at up to a few hundred degrees a second).
    constexpr double kRadPerCount = degToRad((1 << kGyroFsSel) / 131.0);
    rate_ = Vec3(be16(b + 8), be16(b + 10), be16(b + 12)) * kRadPerCount;
    return std::array<std::int16_t, 3>{be16(b), be16(b + 2), be16(b + 4)};
  }

  std::optional<Vec3> lastRate() const override { return rate_; }

  Result<void> standby() override { return writeRegister(0x6B, 0x40); }

  static constexpr int kGyroFsSel = 1;
  std::optional<Vec3> rate_;
};

}  // namespace

std::unique_ptr<I2cAccelerometer> makeMpu6050(std::shared_ptr<I2cBus> bus, std::uint16_t address,
                                              const I2cAccelConfig& config) {
  return std::make_unique<Mpu6050>(std::move(bus), address, config);
}

}  // namespace procam::tilt
