#include "tilt/sample_gate.hpp"

#include <cmath>
#include <ctime>

namespace procam::tilt {

std::uint64_t monotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::uint64_t(ts.tv_sec) * 1000000000ull + std::uint64_t(ts.tv_nsec);
}

Result<TiltSample> SampleGate::check(const TiltSample& s) {
  const Vec3 g = s.specific_force / kStandardGravity;
  if (!g.allFinite()) {
    ++counts_.not_finite;
    return fail(ErrorCode::kInvalidInput, "sample is not finite");
  }
  if (g.cwiseAbs().maxCoeff() > options_.range_g) {
    ++counts_.out_of_range;
    return fail(ErrorCode::kInvalidInput, "sample outside the sensor's range");
  }
  repeats_ = (last_ && *last_ == s.specific_force) ? repeats_ + 1 : 0;
  last_ = s.specific_force;
  if (options_.stuck_limit > 0 && repeats_ + 1 >= options_.stuck_limit) {
    ++counts_.stuck;
    return fail(ErrorCode::kInvalidInput, "sensor output is stuck");
  }
  const double norm = g.norm();
  if (norm < options_.min_norm_g || norm > options_.max_norm_g) {
    ++counts_.bad_norm;
    return fail(ErrorCode::kInvalidInput, "|specific force| is far from 1 g");
  }
  ++counts_.accepted;
  return s;
}

}  // namespace procam::tilt
