#pragma once
// Simulated I2C bus with register-map chips: auto-increment rules, a data-ready bit
// set by produce() and cleared when the data block is read, NACK for absent
// addresses, and a stuck bus that times out every transfer.
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "tilt/i2c/i2c_bus.hpp"

namespace procam::tilt::testing {

struct FakeChip {
  std::uint16_t address = 0;
  std::array<std::uint8_t, 256> regs{};
  bool increment_needs_msb = false;  // LIS3DH: auto-increment only with bit 7 set
  std::uint8_t ready_reg = 0, ready_mask = 0, data_reg = 0;
  std::vector<std::pair<std::uint8_t, std::uint8_t>> writes;

  void produce(const std::array<std::uint8_t, 6>& data) {
    for (int i = 0; i < 6; ++i) regs[std::size_t(data_reg + i)] = data[std::size_t(i)];
    regs[ready_reg] |= ready_mask;
  }
  std::uint8_t lastWrite(std::uint8_t reg) const {
    for (auto it = writes.rbegin(); it != writes.rend(); ++it)
      if (it->first == reg) return it->second;
    return 0xEE;
  }
};

class FakeI2cBus final : public I2cBus {
 public:
  std::vector<FakeChip*> chips;
  bool stuck = false;
  int transfers = 0;

  Result<void> transfer(std::uint16_t address, std::span<const std::uint8_t> write,
                        std::span<std::uint8_t> read) override {
    ++transfers;
    if (stuck) return fail(ErrorCode::kIo, "bus timeout (SDA held low)");
    FakeChip* chip = nullptr;
    for (FakeChip* c : chips)
      if (c->address == address) chip = c;
    if (!chip) return fail(ErrorCode::kNotFound, "no acknowledge");
    if (write.empty()) return {};
    const bool inc = !chip->increment_needs_msb || (write[0] & 0x80);
    std::uint8_t reg = chip->increment_needs_msb ? std::uint8_t(write[0] & 0x7F) : write[0];
    for (std::size_t i = 1; i < write.size(); ++i) {
      chip->regs[reg] = write[i];
      chip->writes.emplace_back(reg, write[i]);
      if (inc) ++reg;
    }
    bool read_data = false;
    for (std::size_t i = 0; i < read.size(); ++i) {
      read[i] = chip->regs[reg];
      read_data = read_data || reg == chip->data_reg + 5;
      if (inc) ++reg;
    }
    if (read_data) chip->regs[chip->ready_reg] &= std::uint8_t(~chip->ready_mask);
    return {};
  }
};

// The chips at their default addresses with their identity registers and data-ready
// bits (ADXL345, MPU-6050, LIS3DH datasheets).
inline FakeChip adxl345() {
  FakeChip c;
  c.address = 0x53;
  c.regs[0x00] = 0xE5;
  c.ready_reg = 0x30, c.ready_mask = 0x80, c.data_reg = 0x32;
  return c;
}
inline FakeChip mpu6050() {
  FakeChip c;
  c.address = 0x68;
  c.regs[0x75] = 0x68;
  c.ready_reg = 0x3A, c.ready_mask = 0x01, c.data_reg = 0x3B;
  return c;
}
inline FakeChip lis3dh() {
  FakeChip c;
  c.address = 0x18;
  c.regs[0x0F] = 0x33;
  c.increment_needs_msb = true;
  c.ready_reg = 0x27, c.ready_mask = 0x08, c.data_reg = 0x28;
  return c;
}

// Datasheet encodings of three axis counts.
inline std::array<std::uint8_t, 6> littleEndian(std::array<int, 3> v) {
  std::array<std::uint8_t, 6> b{};
  for (int a = 0; a < 3; ++a) {
    const auto u = std::uint16_t(std::int16_t(v[std::size_t(a)]));
    b[std::size_t(2 * a)] = std::uint8_t(u & 0xFF);
    b[std::size_t(2 * a + 1)] = std::uint8_t(u >> 8);
  }
  return b;
}
inline std::array<std::uint8_t, 6> bigEndian(std::array<int, 3> v) {
  auto b = littleEndian(v);
  for (int a = 0; a < 3; ++a) std::swap(b[std::size_t(2 * a)], b[std::size_t(2 * a + 1)]);
  return b;
}

}  // namespace procam::tilt::testing
