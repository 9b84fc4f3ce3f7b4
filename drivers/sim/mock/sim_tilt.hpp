#pragma once
// The virtual rig's accelerometer as a tilt::TiltSensor, so that it reaches the daemon
// through the tilt drivers' device wrapper and sample gate (drivers/tilt/plugin), the
// same path as every real tilt sensor.
#include <memory>
#include <string>

#include "sim_world.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::sim::mock {

class SimTiltSensor : public tilt::TiltSensor {
 public:
  SimTiltSensor(std::shared_ptr<SimWorld> world, std::string name)
      : world_(std::move(world)), name_(std::move(name)) {}

  Result<void> open() override { return {}; }
  // The scene's sample at the world's time, in m/s^2 whatever unit the scene reports
  // in (the ABI's unit), with its gyroscope's reading when the sensor has one;
  // kNoDevice while unplugged (sim_unplug.hpp).
  Result<tilt::TiltSample> read() override;
  void close() override {}
  std::string name() const override { return name_; }

 private:
  std::shared_ptr<SimWorld> world_;
  std::string name_;
};

}  // namespace procam::sim::mock
