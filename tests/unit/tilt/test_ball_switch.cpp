#include <gtest/gtest.h>

#include "fake_gpio.hpp"
#include "tilt/gpio/ball_switch.hpp"

namespace procam::tilt {
namespace {

using testing::kMs;
using testing::ScriptedLines;

TEST(Debouncer, BounceSettlesOnceAndGlitchesAreIgnored) {
  Debouncer d({false}, 20 * kMs);
  // Contact bounce: five edges within 2 ms, ending high.
  for (int i = 0; i < 5; ++i) d.edge({0, i % 2 == 0, std::uint64_t(i) * 400'000});
  EXPECT_FALSE(d.settle(10 * kMs));
  EXPECT_FALSE(d.levels()[0]);
  EXPECT_TRUE(d.settle(22 * kMs));
  EXPECT_TRUE(d.levels()[0]);
  // A 5 ms glitch low then high again: the level never changes.
  d.edge({0, false, 100 * kMs});
  d.edge({0, true, 105 * kMs});
  EXPECT_FALSE(d.settle(200 * kMs));
  EXPECT_TRUE(d.levels()[0]);
}

TEST(BallSwitchTilt, DebouncedEdgesGiveCoarseOrientation) {
  auto lines = std::make_unique<ScriptedLines>();
  ScriptedLines* script = lines.get();
  BallSwitchConfig cfg;
  BallSwitchTilt sensor(std::move(lines), cfg);
  ASSERT_TRUE(sensor.open());
  EXPECT_EQ(sensor.orientation(), CoarseOrientation::kUpright);
  auto s = sensor.read();
  ASSERT_TRUE(s);
  EXPECT_NEAR((s->specific_force - Vec3(0, -kStandardGravity, 0)).norm(), 0, 1e-12);
  // Line 1 falls (with bounce) -> levels (1, 0) -> index 1 -> tilted left.
  const std::uint64_t t0 = script->now;
  script->edges = {{1, false, t0 + 1 * kMs}, {1, true, t0 + 2 * kMs}, {1, false, t0 + 3 * kMs}};
  s = sensor.read();
  ASSERT_TRUE(s);
  EXPECT_EQ(sensor.orientation(), CoarseOrientation::kTiltedLeft);
  // Tilted left: the left side is down, so "up" leans towards +x.
  EXPECT_GT(s->specific_force.x(), 0);
  EXPECT_NEAR(s->specific_force.norm(), kStandardGravity, 1e-12);
  // Both low -> upside down: up is +y in the device frame.
  script->edges = {{0, false, script->now + 1 * kMs}};
  ASSERT_TRUE(sensor.read());
  EXPECT_EQ(sensor.orientation(), CoarseOrientation::kUpsideDown);
  EXPECT_NEAR(nominalSpecificForce(CoarseOrientation::kUpsideDown, 0.5).y(), kStandardGravity,
              1e-12);
}

}  // namespace
}  // namespace procam::tilt
