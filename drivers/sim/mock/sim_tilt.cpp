#include "sim_tilt.hpp"

#include "sim/sensors.hpp"
#include "sim_unplug.hpp"

namespace procam::sim::mock {

Result<tilt::TiltSample> SimTiltSensor::read() {
  auto gone = unpluggedNow(name_);
  // A malformed variable was refused when the device was created; it changed since.
  if (!gone) return fail(ErrorCode::kInternal, gone.error().message);
  if (*gone)
    return fail(ErrorCode::kNoDevice,
                "'" + name_ + "' is unplugged (" + std::string(kUnplugVariable) + ")");
  const double t = world_->now();
  auto s = sampleTilt(world_->scene(), name_, t);
  if (!s) return fail(ErrorCode::kIo, s.error().message);
  double unit = 1.0;
  bool gyro = false;
  for (const auto& spec : world_->scene().tiltSensors()) {
    if (spec.name != name_) continue;
    if (spec.report_in_g) unit = kStandardGravity;
    gyro = spec.gyro.has_value();
  }
  tilt::TiltSample out;
  out.specific_force = s->value * unit;
  out.timestamp_ns = static_cast<uint64_t>(t * 1e9);
  if (gyro) {
    // The package's gyroscope, sampled with the same sample (SCENE-FORMAT.md).
    auto w = sampleGyro(world_->scene(), name_, t);
    if (!w) return fail(ErrorCode::kIo, w.error().message);
    out.angular_velocity = w->value;
  }
  return out;
}

}  // namespace procam::sim::mock
