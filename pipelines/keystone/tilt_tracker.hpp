#pragma once
// The sensor side of automatic keystone ([Raskar02] §6.2.2: a tilt sensor gives pitch
// and roll): accelerometer samples, already gated by their driver -> the accelerometer
// calibration -> low-pass, stillness and hysteresis (TiltFilter) -> the direction of
// gravity in the projector frame, only when it changed by enough to matter. Cheap per
// sample.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "core/types.hpp"
#include "keystone/accel_calibration.hpp"
#include "keystone/tilt_filter.hpp"

namespace procam::keystone {

// How the tilt sensor sits on the projector and how to correct its readings.
struct TiltMount {
  Mat3 sensor_from_projector = Mat3::Identity();  // row i = sensor axis i, projector frame
  AccelCalibration calibration;                   // applied to readings in g
  std::string calibration_source;                 // where the calibration came from
};

class TiltTracker {
 public:
  // The filter's own errors (kInvalidInput for options it refuses).
  static Result<TiltTracker> create(const TiltFilterOptions& options, TiltMount mount);

  // One sample: specific force in the sensor frame (m/s^2) at `timestamp_ns`. The
  // direction of gravity in the projector frame when the published estimate changed
  // (past the hysteresis, or a refinement of a still hold), else nullopt. A sample
  // no newer than the last one (a timer polling faster than the sensor) and a
  // non-finite one are ignored.
  std::optional<Vec3> add(const Vec3& specific_force, std::uint64_t timestamp_ns);
  void reset();
  void setCalibration(const AccelCalibration& calibration, std::string source);

  // The mean raw reading (sensor frame, g, before calibration) of the current still
  // hold and how many samples it averages; nullopt while moving.
  std::optional<std::pair<Vec3, long>> stillMean() const;

  bool still() const { return still_; }
  const TiltMount& mount() const { return mount_; }

 private:
  TiltTracker(TiltFilter filter, TiltMount mount)
      : filter_(std::move(filter)), mount_(std::move(mount)) {}

  TiltFilter filter_;
  TiltMount mount_;
  std::optional<std::uint64_t> last_ns_;
  bool still_ = false;
  Vec3 raw_sum_ = Vec3::Zero();  // raw readings (g) of the current still hold
  long raw_count_ = 0;
};

}  // namespace procam::keystone
