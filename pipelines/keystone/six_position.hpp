#pragma once
// Accelerometer calibration from six still holds, one per sensor axis pointing up
// or down, collected one at a time (a real rig: the user turns the projector; the
// virtual rig: the scene is posed), then fitted by calibrateSixPosition.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "keystone/accel_calibration.hpp"

namespace procam::keystone {

// The six still holds of calibrateSixPosition, one per sensor axis
// pointing up or down, collected one at a time (a real rig: the user turns the
// projector; the virtual rig: the scene is posed).
class SixPositionCollector {
 public:
  // A still mean (sensor frame, g, uncalibrated). The pose it fills ("+x" ...
  // "-z": the axis pointing up); kInvalidInput when no axis is within 10
  // degrees of vertical.
  Result<std::string> add(const Vec3& mean_g);
  std::vector<std::string> filled() const;
  std::vector<std::string> missing() const;
  // kTooFewPoints naming the missing poses; the fit's own errors.
  Result<CalibrationFit> solve() const;
  void clear() { poses_ = {}; }

 private:
  std::array<std::optional<Vec3>, 6> poses_;  // +x, -x, +y, -y, +z, -z
};

}  // namespace procam::keystone
