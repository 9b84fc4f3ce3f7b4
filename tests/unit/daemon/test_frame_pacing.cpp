// When a moving projector's keystone frame goes on the wall (daemon/frame_pacing.hpp):
// the tilt sensor's clock against CLOCK_MONOTONIC, the drawing budget and the time a
// frame is asked to go on.
#include <gtest/gtest.h>

#include <limits>

#include "frame_pacing.hpp"

namespace procam::daemon {
namespace {

TEST(SensorClock, TheShortestDeliveryGivesTheOffset) {
  SensorClock clock;
  EXPECT_FALSE(clock.offsetNs());
  EXPECT_FALSE(clock.sensorSeconds(1'000'000'000));
  // Sensor time starts at 0 where CLOCK_MONOTONIC reads 5 s; readings arrive 0.2-3 ms
  // after they were taken.
  const uint64_t epoch = 5'000'000'000;
  const uint64_t delays[] = {3'000'000, 200'000, 1'500'000, 900'000};
  for (int i = 0; i < 4; ++i) {
    const uint64_t taken = static_cast<uint64_t>(i) * 10'000'000;
    clock.add(epoch + taken + delays[i], taken);
  }
  ASSERT_TRUE(clock.offsetNs());
  EXPECT_EQ(*clock.offsetNs(), static_cast<int64_t>(epoch + 200'000));
  // A frame shown at monotonic 5.1 s is at sensor time 0.1 s less the shortest delivery.
  EXPECT_NEAR(*clock.sensorSeconds(epoch + 100'000'000), 0.1 - 200e-6, 1e-12);
}

TEST(SensorClock, AnOldShortDeliveryIsForgotten) {
  SensorClock clock;
  clock.add(1'000, 0);  // 1 us: the clocks' offset then
  for (std::size_t i = 1; i <= SensorClock::kWindow; ++i) {
    clock.add(i * 1'000'000 + 50'000, i * 1'000'000);  // the clock stepped by 49 us
  }
  EXPECT_EQ(*clock.offsetNs(), 50'000);
}

TEST(DrawBudget, TheNinetiethPercentileOfTheLastFrames) {
  DrawBudget b;
  EXPECT_DOUBLE_EQ(b.budget(), DrawBudget::kInitial);
  // 64 draws: 4 ms, every tenth 20 ms (7 of them).
  for (int i = 0; i < 64; ++i) b.add(i % 10 == 3 ? 0.020 : 0.004);
  // The 0.9 quantile (element 56 of 0..63 in order) is one of the 57 short ones: a
  // few stalls do not hold every frame back.
  EXPECT_NEAR(b.budget(), 0.004 + DrawBudget::kMargin, 1e-12);
  // A slow phase: once over a tenth of the window, the budget follows it.
  for (int i = 0; i < 6; ++i) b.add(0.012);
  EXPECT_NEAR(b.budget(), 0.012 + DrawBudget::kMargin, 1e-12);
  // Over after kWindow frames.
  for (std::size_t i = 0; i < DrawBudget::kWindow; ++i) b.add(0.005);
  EXPECT_NEAR(b.budget(), 0.005 + DrawBudget::kMargin, 1e-12);
  // Garbage is not counted; a stall longer than kMax counts as kMax.
  b.add(-1);
  b.add(std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < 8; ++i) b.add(10.0);
  EXPECT_NEAR(b.budget(), DrawBudget::kMax + DrawBudget::kMargin, 1e-12);
}

TEST(PresentTarget, NowPlusTheBudgetOrTheNextVblankFromThen) {
  const uint64_t now = 10'000'000'000;
  EXPECT_EQ(presentTarget(now, 0.008, 0, 0), now + 8'000'000);
  EXPECT_EQ(presentTarget(now, -1, 0, 0), now);
  // 60 Hz, the last vblank 3 ms ago: ready at +8 ms, the next vblank at +13.67 ms.
  const uint64_t period = 16'666'667;
  const uint64_t last = now - 3'000'000;
  EXPECT_EQ(presentTarget(now, 0.008, period, last), last + period);
  // Ready just after that vblank: the one after.
  EXPECT_EQ(presentTarget(now, 0.014, period, last), last + 2 * period);
  // Ready exactly on a vblank: that one.
  EXPECT_EQ(presentTarget(last + period - 8'000'000, 0.008, period, last), last + period);
}

}  // namespace
}  // namespace procam::daemon
