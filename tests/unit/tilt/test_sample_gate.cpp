#include <gtest/gtest.h>

#include <cmath>

#include "tilt/sample_gate.hpp"

namespace procam::tilt {
namespace {

TiltSample sample(double x, double y, double z) {
  return TiltSample{Vec3(x, y, z) * kStandardGravity, 0, std::nullopt};
}

TEST(SampleGate, RejectsAndCountsEachKindOfGarbage) {
  SampleGateOptions o;
  o.range_g = 2;
  o.stuck_limit = 3;
  SampleGate gate(o);
  EXPECT_TRUE(gate.check(sample(0, 0.6, 0.8)));
  EXPECT_FALSE(gate.check(sample(NAN, 0, 1)));
  EXPECT_FALSE(gate.check(sample(0, INFINITY, 1)));
  EXPECT_FALSE(gate.check(sample(0, 0, 2.5)));    // beyond ±2 g
  EXPECT_FALSE(gate.check(sample(0, 0, 0.2)));    // |g| = 0.2
  EXPECT_FALSE(gate.check(sample(0, 1.2, 1.2)));  // |g| = 1.7
  EXPECT_TRUE(gate.check(sample(0.1, 0, 1)));
  EXPECT_TRUE(gate.check(sample(0.1, 0, 1)));
  EXPECT_FALSE(gate.check(sample(0.1, 0, 1)));  // third identical in a row: stuck
  EXPECT_TRUE(gate.check(sample(0.1, 0.01, 1)));
  const SampleCounts& c = gate.counts();
  EXPECT_EQ(c.accepted, 4u);
  EXPECT_EQ(c.not_finite, 2u);
  EXPECT_EQ(c.out_of_range, 1u);
  EXPECT_EQ(c.bad_norm, 2u);
  EXPECT_EQ(c.stuck, 1u);
  EXPECT_EQ(c.rejected(), 6u);
}

}  // namespace
}  // namespace procam::tilt
