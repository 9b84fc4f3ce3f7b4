// ST LIS3DH (datasheet DocID17530): WHO_AM_I 0x0F = 0x33; CTRL_REG1 0x20 (ODR bits 7:4,
// XYZ enable bits 2:0); CTRL_REG4 0x23 (BDU bit 7, FS bits 5:4, HR bit 3); STATUS_REG
// 0x27 (bit 3 ZYXDA); OUT_X_L..OUT_Z_H 0x28..0x2D little-endian, 12-bit left-justified
// in high-resolution mode: 1, 2, 4, 12 mg/digit at ±2, 4, 8, 16 g. Multi-byte reads
// auto-increment only when bit 7 of the register address is set.
#include "tilt/i2c/i2c_chips.hpp"

namespace procam::tilt {
namespace {

class Lis3dh final : public I2cAccelerometer {
 public:
  using I2cAccelerometer::I2cAccelerometer;
  ~Lis3dh() override { close(); }
  std::string name() const override { return "lis3dh"; }

 private:
  Result<void> probe() override { return expectIdentity(0x0F, 0x33, "LIS3DH"); }

  Result<Setup> configure() override {
    int fs = 0;
    while (fs < 3 && (2 << fs) < config().range_g) ++fs;
    static constexpr double kRates[] = {1, 10, 25, 50, 100, 200, 400};
    int odr = 1;
    while (odr < 7 && kRates[odr - 1] < config().rate_hz) ++odr;
    double rate = kRates[odr - 1];
    if (config().rate_hz > 400) odr = 9, rate = 1344;  // normal mode 1.344 kHz
    static constexpr double kMgPerDigit[] = {1, 2, 4, 12};
    if (auto r = writeRegister(0x20, std::uint8_t((odr << 4) | 0x07)); !r)
      return tl::unexpected(r.error());
    if (auto r = writeRegister(0x23, std::uint8_t(0x80 | (fs << 4) | 0x08)); !r)
      return tl::unexpected(r.error());
    // Counts are returned already shifted to 12 bits by readCounts().
    return Setup{kMgPerDigit[fs] / 1000.0, double(2 << fs), rate};
  }

  Result<bool> dataReady() override {
    auto v = readRegister(0x27);
    if (!v) return tl::unexpected(v.error());
    return (*v & 0x08) != 0;
  }

  Result<std::array<std::int16_t, 3>> readCounts() override {
    std::uint8_t b[6];
    if (auto r = readBlock(0x28 | 0x80, b); !r) return tl::unexpected(r.error());
    // Arithmetic shift of the left-justified two's complement value.
    auto twelve = [](const std::uint8_t* p) { return std::int16_t(le16(p) >> 4); };
    return std::array<std::int16_t, 3>{twelve(b), twelve(b + 2), twelve(b + 4)};
  }

  Result<void> standby() override { return writeRegister(0x20, 0x00); }  // power-down
};

}  // namespace

std::unique_ptr<I2cAccelerometer> makeLis3dh(std::shared_ptr<I2cBus> bus, std::uint16_t address,
                                             const I2cAccelConfig& config) {
  return std::make_unique<Lis3dh>(std::move(bus), address, config);
}

}  // namespace procam::tilt
