#pragma once
// Rejection of garbage tilt samples: NaN/Inf, components out of the sensor's range,
// stuck values (the same vector many times in a row: a dead bus or a frozen chip),
// and |f| far from 1 g (the sensor is being shaken or the reading is corrupt). Each
// reason is counted.
#include <cstdint>
#include <optional>

#include "core/error.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::tilt {

struct SampleGateOptions {
  double range_g = 16;      // |component| above this is out of range
  double min_norm_g = 0.5;  // accepted |f| band
  double max_norm_g = 1.5;
  int stuck_limit = 64;  // identical samples in a row that count as stuck; 0: off
};

struct SampleCounts {
  std::uint64_t accepted = 0, not_finite = 0, out_of_range = 0, stuck = 0, bad_norm = 0;
  std::uint64_t rejected() const { return not_finite + out_of_range + stuck + bad_norm; }
};

class SampleGate {
 public:
  explicit SampleGate(const SampleGateOptions& options = {}) : options_(options) {}

  // The sample, or kInvalidInput naming the reason it was rejected.
  Result<TiltSample> check(const TiltSample& sample);
  const SampleCounts& counts() const { return counts_; }
  // Samples the driver itself refused never reach check(); they are counted here: a
  // value beyond the device's range (a HID field outside its logical range) or one
  // that is no number at all (an IIO raw attribute that does not parse).
  void countOutOfRange() { ++counts_.out_of_range; }
  void countNotFinite() { ++counts_.not_finite; }

 private:
  SampleGateOptions options_;
  SampleCounts counts_;
  std::optional<Vec3> last_;
  int repeats_ = 0;
};

}  // namespace procam::tilt
