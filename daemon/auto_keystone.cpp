#include "auto_keystone.hpp"

#include "core/units.hpp"

namespace procam::daemon {

namespace {

bool isRotation(const Mat3& R) {
  return R.allFinite() && (R * R.transpose() - Mat3::Identity()).norm() < 1e-6 &&
         R.determinant() > 0;
}

}  // namespace

Result<TiltMount> mountFromConfig(const KeystoneConfig& config) {
  TiltMount m;
  if (config.mount) {
    for (int i = 0; i < 9; ++i) m.sensor_from_projector(i / 3, i % 3) = (*config.mount)[i];
    if (!isRotation(m.sensor_from_projector)) {
      return fail(ErrorCode::kInvalidInput,
                  "keystone.mount is not a rotation (rows must be orthonormal, det +1)");
    }
  }
  for (int i = 0; i < 3; ++i) {
    m.calibration.offset[i] = config.accel_offset_g[i];
    m.calibration.scale[i] = config.accel_scale[i];
  }
  m.calibration_source = "configuration";
  return m;
}

keystone::TiltFilterOptions tiltFilterOptions(const KeystoneConfig& config) {
  keystone::TiltFilterOptions o;
  o.cutoff_hz = config.cutoff_hz;
  o.hysteresis = degToRad(config.hysteresis_deg);
  return o;
}

}  // namespace procam::daemon
