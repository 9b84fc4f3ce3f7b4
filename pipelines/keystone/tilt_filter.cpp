#include "keystone/tilt_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace procam::keystone {
namespace {

double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

Result<TiltFilter> TiltFilter::create(const TiltFilterOptions& o) {
  const double values[] = {o.cutoff_hz, o.still_threshold, o.still_time, o.settle_time};
  for (double v : values)
    if (!std::isfinite(v) || v <= 0)
      return fail(ErrorCode::kInvalidInput, "tilt filter options must be finite and > 0");
  if (!std::isfinite(o.hysteresis) || o.hysteresis < 0)
    return fail(ErrorCode::kInvalidInput, "hysteresis must be finite and >= 0");
  return TiltFilter(o);
}

void TiltFilter::reset() {
  *this = TiltFilter(options_);
}

Result<TiltOutput> TiltFilter::update(const Vec3& f, double time) {
  if (!f.allFinite() || !std::isfinite(time))
    return fail(ErrorCode::kInvalidInput, "sample or time is not finite");
  if (last_time_ && time <= *last_time_)
    return fail(ErrorCode::kInvalidInput, "sample times must increase");

  if (!last_time_) {
    low_pass_ = f;
    quiet_start_ = time;
  } else {
    const double dt = time - *last_time_;
    const double alpha = 1 - std::exp(-2 * std::numbers::pi * options_.cutoff_hz * dt);
    low_pass_ += alpha * (f - low_pass_);
  }
  last_time_ = time;

  // Quiet period bookkeeping: motion restarts it (and ends stillness).
  if (quiet_count_ > 0 &&
      (low_pass_ - quiet_sum_ / double(quiet_count_)).norm() > options_.still_threshold) {
    quiet_start_ = time;
    quiet_sum_.setZero();
    quiet_count_ = 0;
    still_ = false;
  }
  quiet_sum_ += low_pass_;
  ++quiet_count_;
  if (!still_ && time - quiet_start_ >= options_.still_time) {
    still_ = true;
    still_start_ = time;
    still_sum_.setZero();
    still_count_ = 0;
    next_refinement_ = options_.settle_time;
  }

  TiltOutput out;
  out.still = still_;
  out.filtered = low_pass_;
  if (still_) {
    still_sum_ += f;
    ++still_count_;
    // The mean beats the low-pass once it spans the filter's equivalent boxcar length
    // (noise bandwidth pi/2 f_c -> averaging time 1 / (pi f_c)).
    if (time - still_start_ >= 1 / (std::numbers::pi * options_.cutoff_hz))
      out.filtered = still_sum_ / double(still_count_);
  }

  bool publish = !published_ || angleBetween(*published_, out.filtered) > options_.hysteresis;
  // Refinements at settle_time x 1, 2, 4, ...: each halves the noise variance of the
  // still mean, so a long hold converges with a logarithmic number of updates.
  if (still_ && time - still_start_ >= next_refinement_) {
    next_refinement_ *= 2;
    publish = true;
  }
  if (publish) published_ = out.filtered;
  out.changed = publish;
  out.published = *published_;
  return out;
}

}  // namespace procam::keystone
