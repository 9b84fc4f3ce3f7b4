// Display-to-capture latency from synthetic capture sequences whose switch time
// is known: a camera at a fixed frame period and phase, an optional box exposure,
// ambient light and Gaussian noise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "structured_light/display_latency.hpp"

namespace procam::sl {
namespace {

struct Camera {
  double period = 1.0 / 30;  // s between frames
  double phase = 0;          // first frame's start, s
  double exposure = 0;       // box exposure from the timestamp on; 0: instantaneous
  double ambient = 40;       // DN on both levels
  double sigma = 0;          // Gaussian noise, DN
};

// Frames from `start` to `end`; the region goes from `from` to `to` (DN above
// ambient) at `change` (the shown time plus the true latency).
std::vector<BrightnessSample> capture(const Camera& cam, double start, double end, double change,
                                      double from, double to, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, cam.sigma);
  std::vector<BrightnessSample> out;
  for (double t = start + cam.phase; t < end; t += cam.period) {
    double after;  // fraction of the exposure after the change
    if (cam.exposure > 0) {
      after = std::clamp((t + cam.exposure - change) / cam.exposure, 0.0, 1.0);
    } else {
      after = t >= change ? 1.0 : 0.0;
    }
    const double level = cam.ambient + from + (to - from) * after;
    out.push_back({t, level + (cam.sigma > 0 ? noise(rng) : 0.0)});
  }
  return out;
}

constexpr double kShown = 10.0;

TEST(DisplayLatency, InstantaneousFramesGiveTheLatencyWithinHalfAPeriod) {
  // 0.1 s latency at 30 Hz, every phase of the camera against the switch: the
  // change lies between two frames and the estimate is their middle.
  Camera cam;
  double sum_err = 0;
  int n = 0;
  for (double phase = 0; phase < cam.period; phase += cam.period / 17) {
    cam.phase = phase;
    const double latency = 0.1;
    auto s = capture(cam, kShown - 0.2, kShown + 0.5, kShown + latency, 0, 180);
    auto t = findTransition(s, kShown);
    ASSERT_TRUE(t) << t.error().message;
    EXPECT_LE(std::abs(t->latency - latency), cam.period / 2 + 1e-9) << phase;
    EXPECT_NEAR(t->old_level, 40, 1e-9);
    EXPECT_NEAR(t->new_level, 220, 1e-9);
    // The first frame at the new level is the first one at or after the change.
    EXPECT_GE(s[t->first_new].time, kShown + latency);
    EXPECT_LT(s[t->first_new].time, kShown + latency + cam.period);
    sum_err += t->latency - latency;
    ++n;
  }
  // Uniform phases: the midpoint estimate is unbiased.
  EXPECT_LT(std::abs(sum_err / n), 0.05 * cam.period);
}

TEST(DisplayLatency, NoisyFramesWithAmbientAndBothDirections) {
  Camera cam;
  cam.sigma = 3;
  cam.ambient = 90;
  const double latencies[] = {0.0, 0.016, 0.05, 0.1, 0.25};
  unsigned seed = 1;
  for (double latency : latencies) {
    for (int k = 0; k < 7; ++k) {
      cam.phase = cam.period * k / 7.0;
      // black -> white and white -> black.
      for (bool up : {true, false}) {
        auto s = capture(cam, kShown - 0.15, kShown + latency + 0.2, kShown + latency,
                         up ? 0.0 : 120.0, up ? 120.0 : 0.0, seed++);
        auto t = findTransition(s, kShown);
        ASSERT_TRUE(t) << t.error().message;
        // Noise of 3 DN on a 120 DN step moves the interpolation by a few percent
        // of a frame at most.
        EXPECT_LE(std::abs(t->latency - latency), 0.6 * cam.period) << latency << " " << k;
        EXPECT_GE(t->latency, 0);
        EXPECT_LT(t->noise, 3 * cam.sigma);
      }
    }
  }
}

TEST(DisplayLatency, BoxExposureStaysWithinOnePeriod) {
  // The camera integrates over its whole frame period: one frame catches part of
  // the change. The half-level crossing of start timestamps is half an exposure
  // before the change, so the estimate is early by about that much.
  Camera cam;
  cam.exposure = cam.period;
  for (int k = 0; k < 11; ++k) {
    cam.phase = cam.period * k / 11.0;
    const double latency = 0.12;
    auto s = capture(cam, kShown - 0.1, kShown + 0.4, kShown + latency, 0, 200);
    auto t = findTransition(s, kShown);
    ASSERT_TRUE(t) << t.error().message;
    EXPECT_LE(t->latency, latency + 1e-9);
    EXPECT_GE(t->latency, latency - 0.6 * cam.exposure) << k;
  }
}

TEST(DisplayLatency, ANoiseSpikeBeforeTheChangeIsNotTheChange) {
  Camera cam;
  const double latency = 0.2;
  auto s = capture(cam, kShown - 0.1, kShown + 0.5, kShown + latency, 0, 100);
  // One frame 60 ms after the switch jumps past the midpoint and falls back.
  for (auto& x : s) {
    if (x.time > kShown + 0.05 && x.time < kShown + 0.05 + cam.period) x.brightness += 80;
  }
  auto t = findTransition(s, kShown);
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_LE(std::abs(t->latency - latency), cam.period / 2 + 1e-9);
}

TEST(DisplayLatency, ChangeAtTheSwitchIsZeroLatency) {
  // The last old frame comes before the switch: the estimate lies between the
  // switch and the first new frame.
  Camera cam;
  cam.phase = 0.01;
  auto s = capture(cam, kShown - 0.1, kShown + 0.3, kShown, 0, 100);
  auto t = findTransition(s, kShown);
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_GE(t->latency, 0);
  EXPECT_LE(t->latency, cam.period);
}

TEST(DisplayLatency, TypedErrors) {
  Camera cam;
  cam.sigma = 2;
  // No change at all.
  auto flat = capture(cam, kShown - 0.1, kShown + 0.5, kShown + 0.1, 50, 50);
  auto t = findTransition(flat, kShown);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kIllConditioned);
  // A 4 DN change under 2 DN noise is below the contrast needed.
  auto faint = capture(cam, kShown - 0.1, kShown + 0.5, kShown + 0.1, 50, 54, 3);
  t = findTransition(faint, kShown);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kIllConditioned);
  // The change comes after the last frame.
  auto late = capture(cam, kShown - 0.1, kShown + 0.5, kShown + 0.6, 0, 150, 4);
  t = findTransition(late, kShown);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kIllConditioned);
  // A change that goes back (a flash, not a switch).
  auto flash = capture(cam, kShown - 0.1, kShown + 0.5, kShown + 0.1, 0, 150, 5);
  for (auto& x : flash) {
    if (x.time > kShown + 0.3) x.brightness = 40;
  }
  t = findTransition(flash, kShown);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kNotFound);
  // Nothing before the switch, too little after it, times out of order, NaN.
  auto s = capture(cam, kShown - 0.1, kShown + 0.5, kShown + 0.1, 0, 150, 6);
  t = findTransition(s, s.front().time);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kInvalidInput);
  t = findTransition(s, s[s.size() - 2].time);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kInvalidInput);
  auto swapped = s;
  std::swap(swapped[3], swapped[4]);
  t = findTransition(swapped, kShown);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kInvalidInput);
  auto nan = s;
  nan[5].brightness = std::numeric_limits<double>::quiet_NaN();
  t = findTransition(nan, kShown);
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code, ErrorCode::kInvalidInput);
}

TEST(DisplayLatency, SettledOnceTheLastFramesAgreeAtANewLevel) {
  Camera cam;
  cam.phase = 0.3 * cam.period;  // no frame exactly at the change
  const double latency = 0.1;
  auto all = capture(cam, kShown - 0.1, kShown + 0.4, kShown + latency, 0, 150);
  std::vector<BrightnessSample> seen;
  double settled_at = -1;
  for (const auto& x : all) {
    seen.push_back(x);
    if (transitionSettled(seen, kShown)) {
      settled_at = x.time;
      break;
    }
  }
  // Three frames at the new level: the third one after the change.
  ASSERT_GT(settled_at, 0);
  EXPECT_GE(settled_at, kShown + latency + 2 * cam.period - 1e-9);
  EXPECT_LT(settled_at, kShown + latency + 3 * cam.period);
  auto t = findTransition(seen, kShown);
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_LE(std::abs(t->latency - latency), cam.period / 2 + 1e-9);
  // Never settles without a change.
  auto flat = capture(cam, kShown - 0.1, kShown + 0.4, kShown + latency, 20, 20);
  EXPECT_FALSE(transitionSettled(flat, kShown));
}

TEST(DisplayLatency, StatsAndSettleFrames) {
  auto s = latencyStats({0.11, 0.09, 0.1, 0.13});
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->median, 0.105, 1e-12);
  EXPECT_NEAR(s->spread, 0.04, 1e-12);
  EXPECT_NEAR(s->min, 0.09, 1e-12);
  EXPECT_NEAR(s->max, 0.13, 1e-12);
  EXPECT_EQ(s->count, 4);
  EXPECT_NEAR(latencyStats({0.2, 0.1, 0.3})->median, 0.2, 1e-12);
  EXPECT_FALSE(latencyStats({}));
  EXPECT_FALSE(latencyStats({0.1, std::numeric_limits<double>::infinity()}));
  // 0.1 s at 60 Hz is 6 frames exactly (6.000000000000001 in doubles), plus the margin.
  EXPECT_EQ(settleFrames(0.1, 60, 1), 7);
  EXPECT_EQ(settleFrames(0.101, 60, 1), 8);
  EXPECT_EQ(settleFrames(0.0, 60, 2), 2);
  EXPECT_EQ(settleFrames(0.05, 120, 0), 6);
}

}  // namespace
}  // namespace procam::sl
