#include "tracking/motion_filter.hpp"

#include <cmath>
#include <numbers>

namespace procam::tracking {
namespace {

bool positiveFinite(double v) {
  return std::isfinite(v) && v > 0;
}

// Smoothing factor of a first-order low-pass with cut-off fc at step dt.
double alpha(double fc, double dt) {
  const double tau = 1.0 / (2 * std::numbers::pi * fc);
  return 1.0 / (1.0 + tau / dt);
}

}  // namespace

Result<MotionFilter> MotionFilter::create(const MotionFilterOptions& o) {
  const bool ok =
      o.kind == FilterKind::kOneEuro
          ? positiveFinite(o.one_euro.min_cutoff_hz) && std::isfinite(o.one_euro.beta) &&
                o.one_euro.beta >= 0 && positiveFinite(o.one_euro.derivative_cutoff_hz)
          : positiveFinite(o.kalman.accel_noise) && positiveFinite(o.kalman.measurement_sigma);
  if (!ok || !std::isfinite(o.prediction_s) || o.prediction_s < 0)
    return fail(ErrorCode::kInvalidInput, "bad motion filter options");
  return MotionFilter(o);
}

void MotionFilter::reset() {
  last_time_.reset();
  x_ = v_ = raw_prev_ = Vec3::Zero();
  P_.setZero();
}

FilterOutput MotionFilter::output() const {
  return FilterOutput{x_, v_, x_ + v_ * o_.prediction_s};
}

Result<FilterOutput> MotionFilter::update(const Vec3& z, double time) {
  if (!z.allFinite() || !std::isfinite(time))
    return fail(ErrorCode::kInvalidInput, "non-finite tracker sample");
  if (!last_time_) {
    last_time_ = time;
    x_ = raw_prev_ = z;
    v_.setZero();
    const double r = o_.kalman.measurement_sigma;
    // Velocity unknown at start: a prior wide enough for a head (several m/s).
    P_ << r * r, 0, 0, 25.0;
    return output();
  }
  const double dt = time - *last_time_;
  if (!(dt > 0)) return fail(ErrorCode::kInvalidInput, "tracker sample times must increase");
  last_time_ = time;

  if (o_.kind == FilterKind::kOneEuro) {
    const OneEuroOptions& e = o_.one_euro;
    const Vec3 raw_v = (z - raw_prev_) / dt;
    raw_prev_ = z;
    v_ += alpha(e.derivative_cutoff_hz, dt) * (raw_v - v_);
    const double fc = e.min_cutoff_hz + e.beta * v_.norm();
    x_ += alpha(fc, dt) * (z - x_);
    return output();
  }

  // Constant velocity: F = [1 dt; 0 1], Q from white acceleration of density q.
  const double q = o_.kalman.accel_noise * o_.kalman.accel_noise;
  Eigen::Matrix2d F;
  F << 1, dt, 0, 1;
  Eigen::Matrix2d Q;
  Q << dt * dt * dt / 3, dt * dt / 2, dt * dt / 2, dt;
  P_ = F * P_ * F.transpose() + q * Q;
  x_ += v_ * dt;
  const double r2 = o_.kalman.measurement_sigma * o_.kalman.measurement_sigma;
  const double S = P_(0, 0) + r2;
  const Eigen::Vector2d K = P_.col(0) / S;
  const Vec3 innovation = z - x_;
  x_ += K(0) * innovation;
  v_ += K(1) * innovation;
  P_ -= K * P_.row(0);
  return output();
}

}  // namespace procam::tracking
