#include "keystone/tilt_tracker.hpp"

#include "core/units.hpp"
#include "keystone/orientation.hpp"

namespace procam::keystone {

Result<TiltTracker> TiltTracker::create(const TiltFilterOptions& options, TiltMount mount) {
  auto filter = TiltFilter::create(options);
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

void TiltTracker::setCalibration(const AccelCalibration& calibration, std::string source) {
  mount_.calibration = calibration;
  mount_.calibration_source = std::move(source);
  reset();
}

std::optional<std::pair<Vec3, long>> TiltTracker::stillMean() const {
  if (!still_ || raw_count_ == 0) return std::nullopt;
  return std::pair<Vec3, long>(raw_sum_ / double(raw_count_), raw_count_);
}

std::optional<Vec3> TiltTracker::add(const Vec3& specific_force, std::uint64_t timestamp_ns) {
  // A timer may poll faster than the sensor delivers: the same sample twice.
  if (last_ns_ && timestamp_ns <= *last_ns_) return std::nullopt;
  last_ns_ = timestamp_ns;
  const Vec3 raw_g = specific_force / kStandardGravity;
  auto out =
      filter_.update(mount_.calibration.apply(raw_g), static_cast<double>(timestamp_ns) * 1e-9);
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
  return downFromSpecificForce(mount_.sensor_from_projector.transpose(), out->published)
      .normalized();
}

}  // namespace procam::keystone
