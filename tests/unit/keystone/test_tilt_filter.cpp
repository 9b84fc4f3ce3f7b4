#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "keystone/tilt_filter.hpp"

namespace procam::keystone {
namespace {

constexpr double kRate = 1000;  // Hz

TEST(TiltFilter, FirstOrderStepResponse) {
  // After one time constant 1 / (2 pi fc) a first-order low-pass covers 1 - 1/e.
  TiltFilterOptions o;
  o.cutoff_hz = 10;
  o.hysteresis = 0;
  auto f = TiltFilter::create(o);
  ASSERT_TRUE(f);
  const Vec3 a(0, 0, 1), b(0, 1, 0);
  ASSERT_TRUE(f->update(a, 0));
  const double tau = 1 / (2 * M_PI * 10);
  Result<TiltOutput> out;
  const int steps = int(std::round(tau * kRate * 64));
  for (int i = 1; i <= steps; ++i) out = f->update(b, i / (kRate * 64));
  ASSERT_TRUE(out);
  EXPECT_FALSE(out->still);
  EXPECT_NEAR(out->filtered.y(), 1 - std::exp(-steps / (kRate * 64) / tau), 1e-12);
  EXPECT_NEAR(out->filtered.y(), 1 - std::exp(-1.0), 0.01);
}

TEST(TiltFilter, HysteresisSuppressesSmallChanges) {
  TiltFilterOptions o;
  o.hysteresis = 1e-3;
  o.still_time = 1e3;  // never still here
  auto f = TiltFilter::create(o);
  ASSERT_TRUE(f);
  auto first = f->update(Vec3(0, 0, 1), 0);
  ASSERT_TRUE(first && first->changed);
  // A constant 0.5 mrad offset: the filter converges to it, nothing is published.
  const Vec3 small(std::sin(0.5e-3), 0, std::cos(0.5e-3));
  int published = 0;
  for (int i = 1; i < 2000; ++i) published += f->update(small, i / kRate)->changed;
  EXPECT_EQ(published, 0);
  // 5 mrad: published (once the filtered value passes 1 mrad).
  const Vec3 big(std::sin(5e-3), 0, std::cos(5e-3));
  for (int i = 2000; i < 4000; ++i) published += f->update(big, i / kRate)->changed;
  EXPECT_GE(published, 1);
  EXPECT_LE(published, 5);  // 5 mrad in steps of at least 1 mrad
}

TEST(TiltFilter, StillnessAveragesNoiseDownAndRefinesOnce) {
  TiltFilterOptions o;  // 10 Hz, 0.3 s to still, 2 s to settle
  auto f = TiltFilter::create(o);
  ASSERT_TRUE(f);
  std::mt19937 rng(9);
  const double sigma = 400e-6 * std::sqrt(kRate / 2);  // 400 ug/sqrt(Hz) at 1 kHz
  std::normal_distribution<double> n(0, sigma);
  const Vec3 truth = Vec3(0.2, -0.3, 0.93).normalized();
  int refinements = 0;
  TiltOutput last;
  double t = 0;
  for (int i = 0; i < int(3 * kRate); ++i, t += 1 / kRate) {
    auto out = f->update(truth + Vec3(n(rng), n(rng), n(rng)), t);
    ASSERT_TRUE(out);
    if (out->still && out->changed && t > 2.0) ++refinements;
    last = *out;
  }
  EXPECT_TRUE(last.still);
  EXPECT_EQ(refinements, 1);
  // The still mean over ~2.7 s: per-axis error sigma / sqrt(2700); 4 sigma bound on the
  // worst axis, published equals it after the refinement.
  EXPECT_LT((last.published - truth).cwiseAbs().maxCoeff(), 4 * sigma / std::sqrt(2000.0));
  // Motion ends stillness.
  auto moved = f->update(Vec3(0, 0, 1), t);
  for (int i = 1; i < 20; ++i) moved = f->update(Vec3(0, 0, 1), t + i / kRate);
  EXPECT_FALSE(moved->still);
}

TEST(TiltFilter, TypedErrors) {
  TiltFilterOptions o;
  o.cutoff_hz = 0;
  EXPECT_EQ(TiltFilter::create(o).error().code, ErrorCode::kInvalidInput);
  auto f = TiltFilter::create({});
  ASSERT_TRUE(f);
  ASSERT_TRUE(f->update(Vec3(0, 0, 1), 1.0));
  EXPECT_EQ(f->update(Vec3(0, 0, 1), 1.0).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(f->update(Vec3(NAN, 0, 1), 2.0).error().code, ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::keystone
