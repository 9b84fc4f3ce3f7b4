// Tests for pipelines/tracking/motion_filter: noise reduction, lag within one frame of
// the raw signal and prediction by the display latency.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "tracking/motion_filter.hpp"

namespace procam::tracking {
namespace {

constexpr double kRate = 60;  // Hz, tracker frames
constexpr double kFrame = 1 / kRate;

// Head swaying 0.15 m at 0.5 Hz along x, still in y and z.
Vec3 truth(double t) {
  return Vec3(0.15 * std::sin(2 * std::numbers::pi * 0.5 * t), 0.0, 2.0);
}

struct Trace {
  double lag = 0;        // s, best time shift of the output against the truth
  double still_rms = 0;  // m, on the axis that does not move
  double raw_rms = 0;
};

// Lag = shift s minimising sum |out(t) - truth(t - s)|^2 (grid of 0.1 ms).
Trace simulate(const MotionFilterOptions& o, bool predicted) {
  auto f = MotionFilter::create(o);
  EXPECT_TRUE(f);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0, 1e-3);
  std::vector<double> times, xs;
  double still = 0, raw = 0;
  int count = 0;
  for (int k = 0; k < 600; ++k) {
    const double t = k * kFrame;
    const Vec3 z = truth(t) + Vec3(n(rng), n(rng), n(rng));
    auto out = f->update(z, t);
    EXPECT_TRUE(out);
    if (k < 120) continue;  // settle
    const Vec3 p = predicted ? out->predicted : out->position;
    times.push_back(t);
    xs.push_back(p.x());
    still += (p.y() - truth(t).y()) * (p.y() - truth(t).y());
    raw += (z.y() - truth(t).y()) * (z.y() - truth(t).y());
    ++count;
  }
  Trace r;
  double best = 1e300;
  for (double s = -0.1; s <= 0.1; s += 1e-4) {
    double e = 0;
    for (size_t i = 0; i < times.size(); ++i) {
      const double d = xs[i] - truth(times[i] - s + (predicted ? o.prediction_s : 0)).x();
      e += d * d;
    }
    if (e < best) {
      best = e;
      r.lag = s;
    }
  }
  r.still_rms = std::sqrt(still / count);
  r.raw_rms = std::sqrt(raw / count);
  return r;
}

// Steady-state posterior position sigma of the constant-velocity model (Riccati).
double kalmanSteadySigma(const KalmanOptions& k, double dt) {
  Eigen::Matrix2d P = Eigen::Matrix2d::Identity(), F, Q;
  F << 1, dt, 0, 1;
  Q << dt * dt * dt / 3, dt * dt / 2, dt * dt / 2, dt;
  const double r2 = k.measurement_sigma * k.measurement_sigma;
  for (int i = 0; i < 2000; ++i) {
    P = F * P * F.transpose() + k.accel_noise * k.accel_noise * Q;
    const Eigen::Vector2d K = P.col(0) / (P(0, 0) + r2);
    P -= K * P.row(0);
  }
  return std::sqrt(P(0, 0));
}

TEST(MotionFilter, KalmanLagIsWithinOneFrameAndNoiseFalls) {
  MotionFilterOptions o;
  o.kind = FilterKind::kKalman;
  const Trace r = simulate(o, false);
  const double expected = kalmanSteadySigma(o.kalman, kFrame);
  std::printf("lag %.1f ms, jitter %.2f mm (raw %.2f mm, theory %.2f mm)\n", r.lag * 1e3,
              r.still_rms * 1e3, r.raw_rms * 1e3, expected * 1e3);
  EXPECT_LE(std::abs(r.lag), kFrame);
  // 480 correlated samples: the RMS estimate is good to ~10 %.
  EXPECT_NEAR(r.still_rms / expected, 1.0, 0.15);
  EXPECT_LT(expected, r.raw_rms);
}

TEST(MotionFilter, OneEuroLagIsWithinOneFrameAndNoiseFalls) {
  MotionFilterOptions o;
  o.kind = FilterKind::kOneEuro;
  const Trace r = simulate(o, false);
  std::printf("lag %.1f ms, jitter %.2f mm (raw %.2f mm)\n", r.lag * 1e3, r.still_rms * 1e3,
              r.raw_rms * 1e3);
  EXPECT_LE(std::abs(r.lag), kFrame);
  EXPECT_LT(r.still_rms, 0.7 * r.raw_rms);
}

TEST(MotionFilter, PredictionTracksTheFutureWithinOneFrame) {
  for (FilterKind kind : {FilterKind::kKalman, FilterKind::kOneEuro}) {
    MotionFilterOptions o;
    o.kind = kind;
    o.prediction_s = 0.03;  // display latency
    const Trace r = simulate(o, true);
    std::printf("predicted lag %.1f ms\n", r.lag * 1e3);
    // Compared with truth(t + latency): the remaining lag is within one frame.
    EXPECT_LE(std::abs(r.lag), kFrame) << static_cast<int>(kind);
  }
}

TEST(MotionFilter, RejectsBadOptionsAndTimes) {
  MotionFilterOptions o;
  o.kalman.measurement_sigma = 0;
  EXPECT_FALSE(MotionFilter::create(o));
  o = {};
  o.prediction_s = -1;
  EXPECT_FALSE(MotionFilter::create(o));
  auto f = MotionFilter::create({});
  ASSERT_TRUE(f);
  ASSERT_TRUE(f->update(Vec3::Zero(), 1.0));
  EXPECT_EQ(f->update(Vec3::Zero(), 1.0).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(f->update(Vec3(NAN, 0, 0), 2.0).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::tracking
