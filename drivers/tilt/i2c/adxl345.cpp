// Analog Devices ADXL345 (datasheet rev. G): DEVID 0x00 = 0xE5; BW_RATE 0x2C (rate code
// r: 3200 / 2^(15 - r) Hz); POWER_CTL 0x2D (0x08 measure); INT_SOURCE 0x30 (bit 7
// DATA_READY); DATA_FORMAT 0x31 (FULL_RES bit 3, range bits 1:0); DATAX0..DATAZ1
// 0x32..0x37 little-endian two's complement, 3.9 mg/LSB (1/256 g) in full resolution.
#include <cmath>

#include "tilt/i2c/i2c_chips.hpp"

namespace procam::tilt {
namespace {

class Adxl345 final : public I2cAccelerometer {
 public:
  using I2cAccelerometer::I2cAccelerometer;
  ~Adxl345() override { close(); }
  std::string name() const override { return "adxl345"; }

 private:
  Result<void> probe() override { return expectIdentity(0x00, 0xE5, "ADXL345"); }

  Result<Setup> configure() override {
    int range_code = 0;
    while (range_code < 3 && (2 << range_code) < config().range_g) ++range_code;
    int rate_code = 6;  // 6.25 Hz
    while (rate_code < 15 && 3200.0 / (1 << (15 - rate_code)) < config().rate_hz) ++rate_code;
    if (auto r = writeRegister(0x2D, 0x00); !r) return tl::unexpected(r.error());  // standby
    if (auto r = writeRegister(0x31, std::uint8_t(0x08 | range_code)); !r)
      return tl::unexpected(r.error());
    if (auto r = writeRegister(0x2C, std::uint8_t(rate_code)); !r) return tl::unexpected(r.error());
    if (auto r = writeRegister(0x2D, 0x08); !r) return tl::unexpected(r.error());  // measure
    return Setup{1.0 / 256, double(2 << range_code), 3200.0 / (1 << (15 - rate_code))};
  }

  Result<bool> dataReady() override {
    auto v = readRegister(0x30);
    if (!v) return tl::unexpected(v.error());
    return (*v & 0x80) != 0;
  }

  Result<std::array<std::int16_t, 3>> readCounts() override {
    std::uint8_t b[6];
    if (auto r = readBlock(0x32, b); !r) return tl::unexpected(r.error());
    return std::array<std::int16_t, 3>{le16(b), le16(b + 2), le16(b + 4)};
  }

  Result<void> standby() override { return writeRegister(0x2D, 0x00); }
};

}  // namespace

std::unique_ptr<I2cAccelerometer> makeAdxl345(std::shared_ptr<I2cBus> bus, std::uint16_t address,
                                              const I2cAccelConfig& config) {
  return std::make_unique<Adxl345>(std::move(bus), address, config);
}

}  // namespace procam::tilt
