#pragma once
// Six-position accelerometer calibration: offset and scale per axis. The sensor is held
// still with each axis pointing up and down in turn; every reading then has magnitude
// 1 g, so raw = scale ⊙ f + offset with |f| = 1 g fixes the six unknowns.
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::keystone {

struct AccelCalibration {
  Vec3 offset = Vec3::Zero();  // g
  Vec3 scale = Vec3::Ones();   // dimensionless gain

  Vec3 apply(const Vec3& raw) const { return (raw - offset).cwiseQuotient(scale); }
};

struct CalibrationFit {
  AccelCalibration calibration;
  double rms = 0;  // RMS of | |apply(raw)| - 1 | over the readings, g
};

// `readings`: averaged still readings in g, at least one with each of ±x, ±y, ±z
// pointing up (any order; more than six allowed, then least squares). kTooFewPoints,
// kInvalidInput (NaN), kDegenerate (the readings do not cover the six directions),
// kNoConvergence.
Result<CalibrationFit> calibrateSixPosition(std::span<const Vec3> readings);

}  // namespace procam::keystone
