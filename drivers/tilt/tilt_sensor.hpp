#pragma once
// The tilt sensor interface every backend implements (iio, i2c, hid, gpio, mock). A
// sensor reports specific force in its own frame in m/s^2 — at rest +9.81 along its
// up axis, the plugin ABI's convention (procam_tilt_sample). Devices are closed by the
// destructor (RAII); open() after close() reopens.
#include <cstdint>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "core/types.hpp"
#include "core/units.hpp"

namespace procam::tilt {

using procam::kStandardGravity;  // core/units.hpp

struct TiltSample {
  Vec3 specific_force = Vec3::Zero();  // m/s^2, sensor frame
  std::uint64_t timestamp_ns = 0;      // CLOCK_MONOTONIC unless the device stamps it
  // The package's gyroscope, read with the same sample: rad/s about each sensor axis
  // (right-handed); absent without one (procam_tilt_ops::read_rate).
  std::optional<Vec3> angular_velocity;
};

class TiltSensor {
 public:
  virtual ~TiltSensor() = default;
  TiltSensor() = default;
  TiltSensor(const TiltSensor&) = delete;
  TiltSensor& operator=(const TiltSensor&) = delete;

  virtual Result<void> open() = 0;
  // One new sample; kIo on device errors, kNotFound when no new sample is available.
  virtual Result<TiltSample> read() = 0;
  virtual void close() = 0;
  virtual std::string name() const = 0;
  // A descriptor that becomes readable when a new sample is available, or -1 when the
  // sensor has none and is polled by timer. Valid while open.
  virtual int pollFd() const { return -1; }
};

// CLOCK_MONOTONIC in nanoseconds.
std::uint64_t monotonicNs();

}  // namespace procam::tilt
