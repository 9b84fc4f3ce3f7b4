#pragma once
// The projector's orientation while the hand moves it, from the rate gyroscope in the
// tilt sensor's package. Still, gravity and the camera give the orientation ([Raskar02]
// §6.2.2); moving, the accelerometer's low-pass lags and the camera is not looked at, so
// the last still orientation is carried by the gyroscope: integrated sample by sample
// with the bias learnt while still taken out, and pulled towards the accelerometer's
// gravity with a small gain so that the integration's drift in pitch and roll does not
// grow (a complementary filter: Mahony, Hamel and Pflimlin 2008, without the integral
// term; the bias comes from the still holds instead).
//
// R maps the wall frame to the projector frame (keystone/orientation.hpp); a projector
// turning at angular velocity w (projector frame, rad/s) has dR/dt = -[w]x R.
#include <cstdint>
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::keystone {

struct GyroOrientationOptions {
  double gravity_gain = 0.5;  // 1/s: how fast a tilt error is pulled towards gravity
  // Readings further apart than this (a stalled poll, a replugged sensor) end the
  // carrying: what turned in between is not known. Shorter gaps are integrated with the
  // mean of the two rates.
  double max_step_s = 0.5;
};

class GyroOrientation {
 public:
  // kInvalidInput for a gain < 0 or a step <= 0 (non-finite included).
  static Result<GyroOrientation> create(const GyroOrientationOptions& options = {});

  // From orientation R (wall -> projector) known at time_ns, turning at `rate` then
  // (projector frame, rad/s, bias removed: zero for a projector held still).
  void start(const Mat3& R, std::uint64_t time_ns, const Vec3& rate = Vec3::Zero());
  void stop() { running_ = false; }
  bool running() const { return running_; }

  // One gyroscope reading (projector frame, rad/s, bias removed) at time_ns, with the
  // accelerometer's direction of gravity (projector frame, any length) when it has
  // one: the rotation since the last reading is applied with the mean of the two rates
  // (trapezoid), then the tilt pulled towards gravity. A reading no newer than the last
  // or a non-finite input moves nothing; a gap over max_step_s stops the carrying
  // (running() turns false).
  void update(const Vec3& rate, const std::optional<Vec3>& down, std::uint64_t time_ns);

  const Mat3& R() const { return R_; }
  // The orientation lead_s seconds after the last reading: turning at its rate, which
  // changes at the angular acceleration of the last readings (low-passed over
  // kAccelerationTau), to second order in lead_s. R() itself for lead_s <= 0. What an
  // output shows when its frame reaches the wall lead_s later.
  Mat3 predicted(double lead_s) const;
  const Vec3& acceleration() const { return acceleration_; }  // rad/s^2, projector frame

  // s: one reading of a 100 Hz gyroscope, ten at 1 kHz.
  static constexpr double kAccelerationTau = 0.01;

 private:
  explicit GyroOrientation(const GyroOrientationOptions& options) : options_(options) {}

  GyroOrientationOptions options_;
  bool running_ = false;
  Mat3 R_ = Mat3::Identity();
  std::uint64_t last_ns_ = 0;
  std::optional<Vec3> last_rate_;
  Vec3 acceleration_ = Vec3::Zero();
};

// The gyroscope's bias: the mean of its readings while the projector is held still (a
// hold of at least `min_samples`), kept while it moves. Once a hold has 10 readings, one
// farther than `outlier` from their mean is left out: the first readings of a turn
// arrive before the accelerometer's filter sees the motion.
class GyroBias {
 public:
  explicit GyroBias(long min_samples = 50, double outlier = 0.035)
      : min_samples_(min_samples), outlier_(outlier) {}
  void addStill(const Vec3& rate);
  void endHold();  // the projector moves: the hold's mean, if long enough, is the bias
  // The bias (projector frame, rad/s): the current hold's mean once it is long enough,
  // else the last long enough hold's; zero before.
  Vec3 value() const;
  bool known() const { return known_ || count_ >= min_samples_; }

 private:
  long min_samples_;
  double outlier_;
  Vec3 sum_ = Vec3::Zero();
  long count_ = 0;
  Vec3 bias_ = Vec3::Zero();
  bool known_ = false;
};

}  // namespace procam::keystone
