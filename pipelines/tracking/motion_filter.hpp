#pragma once
// Position filters for tracker readings ([Raskar02] §4.1.4: readings are low-pass filtered
// before use), with prediction ahead by the display latency (the rendered frame is
// seen that much later than the reading):
//  - One Euro: adaptive first-order low-pass whose cut-off rises with speed
//    (min_cutoff + beta |v|), so jitter is removed at rest and lag stays small in motion;
//  - Kalman: constant-velocity model per axis, white-acceleration process noise.
// Prediction extrapolates the filtered position with the filtered velocity.
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::tracking {

enum class FilterKind { kOneEuro, kKalman };

struct OneEuroOptions {
  double min_cutoff_hz = 1.0;
  double beta = 50.0;  // 1/m: cut-off increase per m/s
  double derivative_cutoff_hz = 5.0;
};

struct KalmanOptions {
  double accel_noise = 0.2;         // m/s^2 / sqrt(Hz): white-acceleration density
  double measurement_sigma = 1e-3;  // m
};

struct MotionFilterOptions {
  FilterKind kind = FilterKind::kKalman;
  OneEuroOptions one_euro;
  KalmanOptions kalman;
  double prediction_s = 0;  // display latency to predict over
};

struct FilterOutput {
  Vec3 position = Vec3::Zero();   // filtered, at the sample's time
  Vec3 velocity = Vec3::Zero();   // m/s
  Vec3 predicted = Vec3::Zero();  // position + velocity * prediction_s
};

class MotionFilter {
 public:
  // kInvalidInput for non-positive or non-finite options (prediction_s may be 0).
  static Result<MotionFilter> create(const MotionFilterOptions& options);

  // `time` in seconds, strictly increasing; kInvalidInput otherwise or for NaN/Inf.
  Result<FilterOutput> update(const Vec3& position, double time);
  void reset();

 private:
  explicit MotionFilter(const MotionFilterOptions& o) : o_(o) {}
  FilterOutput output() const;

  MotionFilterOptions o_;
  std::optional<double> last_time_;
  Vec3 x_ = Vec3::Zero();  // position
  Vec3 v_ = Vec3::Zero();  // velocity
  Vec3 raw_prev_ = Vec3::Zero();
  // Kalman covariance per axis (identical for all three: same model and noise).
  Eigen::Matrix2d P_ = Eigen::Matrix2d::Zero();
};

}  // namespace procam::tracking
