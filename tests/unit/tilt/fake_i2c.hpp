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

}  // namespace procam::tilt::testing
