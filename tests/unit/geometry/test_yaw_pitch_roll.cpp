// procamd's one yaw/pitch/roll convention (ARCHITECTURE.md, "Frames and conventions"):
// the sign of each angle in the reference frame and in a parent device's frame, and the
// conversions back from a rotation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/units.hpp"
#include "geometry/yaw_pitch_roll.hpp"

namespace procam::geom {
namespace {

TEST(YawPitchRoll, ZeroAnglesLookAlongPlusYUpright) {
  const Mat3 B = worldFromDevice({});
  EXPECT_TRUE(B.col(0).isApprox(Vec3::UnitX()));   // image right
  EXPECT_TRUE(B.col(1).isApprox(-Vec3::UnitZ()));  // image down
  EXPECT_TRUE(B.col(2).isApprox(Vec3::UnitY()));   // optical axis
  EXPECT_TRUE(parentFromChild({}).isApprox(Mat3::Identity()));
}

TEST(YawPitchRoll, EachAngleTurnsTheDocumentedWayInTheWorld) {
  for (const double a : {degToRad(30), degToRad(-30)}) {
    // Yaw: the optical axis turns right (towards +X) for a > 0, left for a < 0.
    EXPECT_TRUE(worldFromDevice({0, 0, a}).col(2).isApprox(Vec3(std::sin(a), std::cos(a), 0))) << a;
    // Pitch: the optical axis rises (towards +Z) for a > 0.
    EXPECT_TRUE(worldFromDevice({a, 0, 0}).col(2).isApprox(Vec3(0, std::cos(a), std::sin(a)))) << a;
    // Roll: the image's right side (device x) goes down (towards -Z) for a > 0.
    EXPECT_TRUE(worldFromDevice({0, a, 0}).col(0).isApprox(Vec3(std::cos(a), 0, -std::sin(a))))
        << a;
  }
}

TEST(YawPitchRoll, EachAngleTurnsTheDocumentedWayInAParentFrame) {
  // Parent device frame: x right, y down, z forward.
  for (const double a : {degToRad(3), degToRad(-3)}) {
    EXPECT_TRUE(parentFromChild({0, 0, a}).col(2).isApprox(Vec3(std::sin(a), 0, std::cos(a))))
        << a;  // yaw > 0: to the parent's right
    EXPECT_TRUE(parentFromChild({a, 0, 0}).col(2).isApprox(Vec3(0, -std::sin(a), std::cos(a))))
        << a;  // pitch > 0: up, the parent's -y
    EXPECT_TRUE(parentFromChild({0, a, 0}).col(0).isApprox(Vec3(std::cos(a), std::sin(a), 0)))
        << a;  // roll > 0: the right side down, the parent's +y
  }
}

TEST(YawPitchRoll, RotationsAndAnglesRoundTrip) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pitch(-80, 80), roll(-170, 170), yaw(-170, 170);
  for (int i = 0; i < 200; ++i) {
    const YawPitchRoll a{degToRad(pitch(rng)), degToRad(roll(rng)), degToRad(yaw(rng))};
    const Mat3 R = rotationFromAngles(a);
    ASSERT_NEAR((R * R.transpose() - Mat3::Identity()).norm(), 0, 1e-14);
    EXPECT_NEAR((R - worldFromDevice(a).transpose()).norm(), 0, 1e-15);
    // A parent at zero angles is the reference frame itself.
    EXPECT_NEAR((parentFromChild(a) - worldFromDevice({}).transpose() * worldFromDevice(a)).norm(),
                0, 1e-14);
    const YawPitchRoll b = anglesFromRotation(R);
    EXPECT_NEAR(b.pitch, a.pitch, 1e-12);
    EXPECT_NEAR(b.roll, a.roll, 1e-12);
    EXPECT_NEAR(b.yaw, a.yaw, 1e-12);
  }
}

}  // namespace
}  // namespace procam::geom
