#pragma once
// Accelerometer stream -> a gravity estimate that changes only when it matters.
//  - low-pass: first order, cut-off f_c, per-sample time step (irregular rates allowed);
//  - stillness: the low-passed vector stays within `still_threshold` of the mean since
//    the current quiet period began, for `still_time`;
//  - once still, a fresh mean of the raw samples replaces the low-pass output (white
//    noise then falls as 1/sqrt(T) instead of staying at the filter's bandwidth);
//  - hysteresis: the published vector changes only when it turns by more than
//    `hysteresis` (a smaller change costs nothing downstream), plus refinement
//    publications after 1, 2, 4, ... x `settle_time` of stillness.
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::keystone {

struct TiltFilterOptions {
  double cutoff_hz = 10;
  double still_threshold = 0.01;  // g
  double still_time = 0.3;        // s
  double settle_time = 2.0;       // s of averaging before the first refinement
  double hysteresis = 0.5e-3;     // rad
};

struct TiltOutput {
  Vec3 published = Vec3::Zero();  // the vector downstream should use (sensor frame, g)
  Vec3 filtered = Vec3::Zero();   // current best estimate (low-pass or still mean)
  bool still = false;
  bool changed = false;  // `published` changed with this sample
};

class TiltFilter {
 public:
  // kInvalidInput for non-positive or non-finite options.
  static Result<TiltFilter> create(const TiltFilterOptions& options);

  // `specific_force` in g (calibrated), `time` in seconds, strictly increasing.
  Result<TiltOutput> update(const Vec3& specific_force, double time);
  void reset();

 private:
  explicit TiltFilter(const TiltFilterOptions& options) : options_(options) {}

  TiltFilterOptions options_;
  std::optional<double> last_time_;
  Vec3 low_pass_ = Vec3::Zero();
  // Quiet period: mean of the low-pass output since it began.
  double quiet_start_ = 0;
  Vec3 quiet_sum_ = Vec3::Zero();
  long quiet_count_ = 0;
  // Still period: mean of raw samples since stillness was declared.
  bool still_ = false;
  double still_start_ = 0;
  Vec3 still_sum_ = Vec3::Zero();
  long still_count_ = 0;
  double next_refinement_ = 0;  // still time of the next refinement publication
  std::optional<Vec3> published_;
};

}  // namespace procam::keystone
