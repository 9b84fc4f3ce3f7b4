#pragma once
// The virtual rig's accelerometer as a tilt::TiltSensor, so that it reaches the daemon
// through the tilt drivers' device wrapper and sample gate (drivers/tilt/plugin), the
// same path as every real tilt sensor. It samples at the scene's output data rate into a
// FIFO, as an IIO buffered device does: a reader that falls behind gets every sample
// in order (up to kFifoDepth of them), not the newest alone.
#include <memory>
#include <string>

#include "core/unique_fd.hpp"
#include "sim_world.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::sim::mock {

class SimTiltSensor : public tilt::TiltSensor {
 public:
  // Samples a reader may fall behind by before the oldest are lost (an MPU-6050's
  // 1024-byte FIFO holds 85 accelerometer and gyroscope samples; 2.56 s at 100 Hz).
  static constexpr long long kFifoDepth = 256;

  SimTiltSensor(std::shared_ptr<SimWorld> world, std::string name);

  // Creates the descriptor that is readable while a sample waits.
  Result<void> open() override;
  // The oldest sample not yet read, or the newest again when none waits; in m/s^2
  // whatever unit the scene reports in (the ABI's unit), with its gyroscope's reading
  // when the sensor has one; kNoDevice while unplugged (sim_unplug.hpp).
  Result<tilt::TiltSample> read() override;
  void close() override { timer_.reset(); }
  std::string name() const override { return name_; }
  int pollFd() const override { return timer_.get(); }

 private:
  // Makes the descriptor readable at the world time of sample `k` (at once when past).
  void armFor(long long k);

  std::shared_ptr<SimWorld> world_;
  std::string name_;
  // The scene's sensor, read once: its output data rate, the factor from its units to
  // m/s^2, whether its package has a gyroscope.
  double rate_hz_ = 100.0;
  double unit_ = 1.0;
  bool gyro_ = false;
  UniqueFd timer_;
  long long next_ = -1;  // the sample the next read returns; -1: none read yet
};

}  // namespace procam::sim::mock
