#include "tilt/i2c/i2c_accelerometer.hpp"

#include <cstdio>
#include <thread>

namespace procam::tilt {

Result<std::uint8_t> I2cAccelerometer::readRegister(std::uint8_t reg) {
  std::uint8_t value = 0;
  auto r = bus_->transfer(address_, std::span<const std::uint8_t>(&reg, 1),
                          std::span<std::uint8_t>(&value, 1));
  if (!r) return tl::unexpected(r.error());
  return value;
}

Result<void> I2cAccelerometer::writeRegister(std::uint8_t reg, std::uint8_t value) {
  const std::uint8_t buf[2] = {reg, value};
  return bus_->transfer(address_, buf, {});
}

Result<void> I2cAccelerometer::readBlock(std::uint8_t first_reg, std::span<std::uint8_t> out) {
  return bus_->transfer(address_, std::span<const std::uint8_t>(&first_reg, 1), out);
}

Result<void> I2cAccelerometer::expectIdentity(std::uint8_t reg, std::uint8_t expected,
                                              const char* chip) {
  auto id = readRegister(reg);
  if (!id) return tl::unexpected(id.error());
  if (*id != expected) {
    char msg[96];
    std::snprintf(msg, sizeof msg,
                  "%s at 0x%02x: identity register 0x%02x reads 0x%02x, expected 0x%02x", chip,
                  address_, reg, *id, expected);
    return fail(ErrorCode::kNotFound, msg);
  }
  return {};
}

Result<void> I2cAccelerometer::open() {
  if (open_) return {};
  if (!(config_.range_g > 0) || !(config_.rate_hz > 0) || config_.max_polls < 1)
    return fail(ErrorCode::kInvalidInput, name() + ": range, rate and polls must be > 0");
  if (auto p = probe(); !p) return p;
  auto setup = configure();
  if (!setup) return tl::unexpected(setup.error());
  g_per_count_ = setup->g_per_count;
  range_g_ = setup->range_g;
  rate_hz_ = setup->rate_hz;
  open_ = true;
  return {};
}

namespace {

// After setup a NACK means the chip went away, not "no sample yet" (kNotFound).
Error lostChip(const Error& e, const std::string& chip) {
  if (e.code != ErrorCode::kNotFound) return e;
  return {ErrorCode::kIo, chip + ": stopped acknowledging (" + e.message + ")"};
}

}  // namespace

Result<TiltSample> I2cAccelerometer::read() {
  if (!open_) return fail(ErrorCode::kIo, name() + ": not open");
  for (int poll = 0; poll < config_.max_polls; ++poll) {
    auto ready = dataReady();
    if (!ready) return tl::unexpected(lostChip(ready.error(), name()));
    if (*ready) {
      auto counts = readCounts();
      if (!counts) return tl::unexpected(lostChip(counts.error(), name()));
      TiltSample s;
      s.timestamp_ns = monotonicNs();
      for (int a = 0; a < 3; ++a)
        s.specific_force(a) = (*counts)[a] * g_per_count_ * kStandardGravity;
      s.angular_velocity = lastRate();
      return s;
    }
    if (config_.poll_interval.count() > 0) std::this_thread::sleep_for(config_.poll_interval);
  }
  return fail(ErrorCode::kNotFound, name() + ": no data ready");
}

void I2cAccelerometer::close() {
  if (!open_) return;
  open_ = false;
  (void)standby();  // best effort: the chip may already be gone
}

}  // namespace procam::tilt
