#include "auto_keystone.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/units.hpp"
#include "keystone/keystone_solver.hpp"
#include "state_file.hpp"

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

Result<TiltTracker> TiltTracker::create(const KeystoneConfig& config, TiltMount mount) {
  keystone::TiltFilterOptions o;
  o.cutoff_hz = config.cutoff_hz;
  o.hysteresis = degToRad(config.hysteresis_deg);
  auto filter = keystone::TiltFilter::create(o);
  if (!filter) return tl::unexpected(filter.error());
  return TiltTracker(std::move(*filter), std::move(mount));
}

void TiltTracker::reset() {
  filter_.reset();
  last_ns_.reset();
  still_ = false;
  raw_sum_.setZero();
  raw_count_ = 0;
}

void TiltTracker::setCalibration(const keystone::AccelCalibration& calibration,
                                 std::string source) {
  mount_.calibration = calibration;
  mount_.calibration_source = std::move(source);
  reset();
}

std::optional<std::pair<Vec3, long>> TiltTracker::stillMean() const {
  if (!still_ || raw_count_ == 0) return std::nullopt;
  return std::pair<Vec3, long>(raw_sum_ / double(raw_count_), raw_count_);
}

std::optional<Vec3> TiltTracker::add(const procam_tilt_sample& s) {
  // A timer may poll faster than the sensor delivers: the same sample twice.
  if (last_ns_ && s.timestamp_ns <= *last_ns_) return std::nullopt;
  last_ns_ = s.timestamp_ns;
  // The driver dropped garbage samples already (its sample gate).
  const Vec3 raw_g =
      Vec3(s.specific_force[0], s.specific_force[1], s.specific_force[2]) / kStandardGravity;
  auto out =
      filter_.update(mount_.calibration.apply(raw_g), static_cast<double>(s.timestamp_ns) * 1e-9);
  if (!out) return std::nullopt;  // non-finite input: the filter refuses it
  if (!out->still) {
    raw_sum_.setZero();
    raw_count_ = 0;
  } else {
    raw_sum_ += raw_g;
    ++raw_count_;
  }
  still_ = out->still;
  if (!out->changed) return std::nullopt;
  // downFromSpecificForce takes the sensor -> projector rotation.
  return keystone::downFromSpecificForce(mount_.sensor_from_projector.transpose(), out->published)
      .normalized();
}

Result<KeystoneEstimate> solveFromDown(const ProjectorModel& projector, const Vec3& down,
                                       int content_width, int content_height) {
  auto angles = keystone::tiltFromDown(down);
  if (!angles) return tl::unexpected(angles.error());
  keystone::KeystoneProblem p;
  p.K = projector.K;
  p.width = projector.width;
  p.height = projector.height;
  p.R = keystone::rotationFromAngles(*angles);
  p.content_width = content_width;
  p.content_height = content_height;
  auto s = keystone::solveKeystone(p);
  if (!s) return tl::unexpected(s.error());
  KeystoneEstimate e;
  e.H = s->H;
  e.down = down;
  e.angles = *angles;
  e.scale = s->scale;
  e.content_width = content_width;
  e.content_height = content_height;
  return e;
}

}  // namespace procam::daemon
