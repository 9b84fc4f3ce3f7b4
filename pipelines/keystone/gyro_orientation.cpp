#include "keystone/gyro_orientation.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace procam::keystone {

Result<GyroOrientation> GyroOrientation::create(const GyroOrientationOptions& options) {
  if (!(options.gravity_gain >= 0) || !std::isfinite(options.gravity_gain) ||
      !(options.max_step_s > 0) || !std::isfinite(options.max_step_s)) {
    return fail(ErrorCode::kInvalidInput,
                "gyro orientation: the gravity gain must be >= 0 and the step > 0, both finite");
  }
  return GyroOrientation(options);
}

void GyroOrientation::start(const Mat3& R, std::uint64_t time_ns, const Vec3& rate) {
  R_ = R;
  last_ns_ = time_ns;
  last_rate_ = rate.allFinite() ? rate : Vec3::Zero();
  acceleration_.setZero();
  running_ = true;
}

void GyroOrientation::update(const Vec3& rate, const std::optional<Vec3>& down,
                             std::uint64_t time_ns) {
  if (!running_ || time_ns <= last_ns_ || !rate.allFinite()) return;
  const double dt = static_cast<double>(time_ns - last_ns_) * 1e-9;
  last_ns_ = time_ns;
  if (dt > options_.max_step_s) {
    running_ = false;
    return;
  }
  // dR/dt = -[w]x R: over dt, R <- exp(-[w dt]x) R (the mean rate of the step).
  const Vec3 w = last_rate_ ? 0.5 * (rate + *last_rate_) : rate;
  if (last_rate_) {
    // Differences of noisy rates: low-passed so that a fast, noisy gyroscope's
    // acceleration stays usable (a lag of kAccelerationTau costs the prediction the
    // jerk's share, far below a pixel for a hand's motion).
    const Vec3 raw = (rate - *last_rate_) / dt;
    acceleration_ += (1.0 - std::exp(-dt / kAccelerationTau)) * (raw - acceleration_);
  }
  last_rate_ = rate;
  const double angle = w.norm() * dt;
  if (angle > 0) R_ = Eigen::AngleAxisd(-angle, w.normalized()).toRotationMatrix() * R_;
  // Gravity: the wall frame's down (0, 0, -1) as R predicts it, turned towards the
  // measured one about their common normal.
  if (down && down->allFinite() && down->norm() > 0 && options_.gravity_gain > 0) {
    const Vec3 predicted = R_ * Vec3(0, 0, -1);
    const Vec3 axis = predicted.cross(down->normalized());
    const double s = axis.norm();
    if (s > 1e-12) {
      // Proportional: a tilt error decays as exp(-gain t), the accelerometer's noise
      // averaged over 1 / gain seconds.
      const double turn = std::min(1.0, options_.gravity_gain * dt) * std::asin(std::min(1.0, s));
      R_ = Eigen::AngleAxisd(turn, axis / s).toRotationMatrix() * R_;
    }
  }
  // Keep R a rotation against rounding over many steps.
  const Eigen::Quaterniond q(R_);
  R_ = q.normalized().toRotationMatrix();
}

Mat3 GyroOrientation::predicted(double lead_s) const {
  if (!(lead_s > 0) || !std::isfinite(lead_s) || !last_rate_) return R_;
  // w(t) = rate + acceleration t: the rotation vector turned through over the lead.
  const Vec3 phi = *last_rate_ * lead_s + 0.5 * acceleration_ * lead_s * lead_s;
  const double angle = phi.norm();
  if (!(angle > 0) || !std::isfinite(angle)) return R_;
  return Eigen::AngleAxisd(-angle, phi / angle).toRotationMatrix() * R_;
}

void GyroBias::addStill(const Vec3& rate) {
  if (!rate.allFinite()) return;
  if (count_ >= 10 && (rate - sum_ / static_cast<double>(count_)).norm() > outlier_) return;
  sum_ += rate;
  ++count_;
}

Vec3 GyroBias::value() const {
  // The freshest: a gyroscope's bias drifts as it warms up.
  if (count_ >= min_samples_) return sum_ / static_cast<double>(count_);
  return bias_;
}

void GyroBias::endHold() {
  if (count_ >= min_samples_) {
    bias_ = sum_ / static_cast<double>(count_);
    known_ = true;
  }
  sum_.setZero();
  count_ = 0;
}

}  // namespace procam::keystone
