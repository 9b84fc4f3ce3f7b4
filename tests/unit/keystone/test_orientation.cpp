#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/units.hpp"
#include "keystone/orientation.hpp"

namespace procam::keystone {
namespace {

Vec3 opticalAxisInWall(const Mat3& R) {
  return R.transpose() * Vec3::UnitZ();
}

TEST(Orientation, ReferencePoseLooksSquareAtTheWallUpright) {
  const Mat3 R = rotationFromAngles({});
  EXPECT_NEAR((opticalAxisInWall(R) - Vec3::UnitY()).norm(), 0, 1e-15);
  EXPECT_NEAR((R * Vec3(0, 0, -1) - Vec3::UnitY()).norm(), 0, 1e-15);  // gravity = image down
  EXPECT_NEAR((R * Vec3::UnitX() - Vec3::UnitX()).norm(), 0, 1e-15);
}

TEST(Orientation, SignsOfTheDocumentedConvention) {
  // pitch up: optical axis rises; yaw right: it moves to +X; roll clockwise seen from
  // behind: the image's right side (projector +x) goes down.
  EXPECT_NEAR(opticalAxisInWall(rotationFromAngles({10 * kDeg, 0, 0})).z(), std::sin(10 * kDeg),
              1e-15);
  EXPECT_NEAR(opticalAxisInWall(rotationFromAngles({0, 0, 10 * kDeg})).x(), std::sin(10 * kDeg),
              1e-15);
  EXPECT_NEAR((rotationFromAngles({0, 10 * kDeg, 0}).transpose() * Vec3::UnitX()).z(),
              -std::sin(10 * kDeg), 1e-15);
}

TEST(Orientation, AnglesRoundTripAndGravityFormula) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> pitch(-80, 80), roll(-170, 170), yaw(-80, 80);
  for (int i = 0; i < 200; ++i) {
    const Angles a{pitch(rng) * kDeg, roll(rng) * kDeg, yaw(rng) * kDeg};
    const Mat3 R = rotationFromAngles(a);
    ASSERT_NEAR((R.transpose() * R - Mat3::Identity()).norm(), 0, 1e-14);
    ASSERT_NEAR(R.determinant(), 1, 1e-14);
    const Angles b = anglesFromRotation(R);
    EXPECT_NEAR(b.pitch, a.pitch, 1e-12);
    EXPECT_NEAR(b.roll, a.roll, 1e-12);
    EXPECT_NEAR(b.yaw, a.yaw, 1e-12);
    const Vec3 down = R * Vec3(0, 0, -1);
    const Vec3 expected(std::sin(a.roll) * std::cos(a.pitch), std::cos(a.roll) * std::cos(a.pitch),
                        -std::sin(a.pitch));
    EXPECT_NEAR((down - expected).norm(), 0, 1e-14);
    auto t = tiltFromDown(3.7 * down);
    ASSERT_TRUE(t);
    EXPECT_NEAR(t->pitch, a.pitch, 1e-12);
    EXPECT_NEAR(t->roll, a.roll, 1e-12);
  }
}

TEST(Orientation, FusionRecoversTheFullRotationFromGravityAndWallNormal) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pitch(-45, 45), roll(-20, 20), yaw(-30, 30);
  for (int i = 0; i < 200; ++i) {
    const Angles a{pitch(rng) * kDeg, roll(rng) * kDeg, yaw(rng) * kDeg};
    const Mat3 R = rotationFromAngles(a);
    const Vec3 down = R * Vec3(0, 0, -1);
    const Vec3 normal = (i % 2 ? 1.0 : -1.0) * (R * Vec3::UnitY());  // either sign
    auto fused = fuseOrientation(down, normal);
    ASSERT_TRUE(fused);
    EXPECT_NEAR((fused->R - R).norm(), 0, 1e-12);
    EXPECT_NEAR(fused->wall_tilt, 0, 1e-7);
    // A normal tilted out of the horizontal by 2° about the wall's X axis: yaw,
    // pitch and roll stay those of gravity and the horizontal part; the check reports 2°.
    const Vec3 tilted =
        R * Eigen::AngleAxisd(2 * kDeg, Vec3::UnitX()).toRotationMatrix() * Vec3::UnitY();
    auto f2 = fuseOrientation(down, tilted);
    ASSERT_TRUE(f2);
    EXPECT_NEAR((f2->R - R).norm(), 0, 1e-12);
    EXPECT_NEAR(f2->wall_tilt, 2 * kDeg, 1e-12);
  }
}

TEST(Orientation, SingleSensorModes) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> angle(-40, 40);
  for (int i = 0; i < 100; ++i) {
    const Angles tilt{angle(rng) * kDeg, angle(rng) * kDeg, 0};
    const Mat3 Rt = rotationFromAngles(tilt);
    auto from_down = rotationFromDown(Rt * Vec3(0, 0, -1));
    ASSERT_TRUE(from_down);
    EXPECT_NEAR((*from_down - Rt).norm(), 0, 1e-12);
    const Angles cam{angle(rng) * kDeg, 0, angle(rng) * kDeg};
    const Mat3 Rc = rotationFromAngles(cam);
    auto from_normal = rotationFromWallNormal(-(Rc * Vec3::UnitY()));
    ASSERT_TRUE(from_normal);
    EXPECT_NEAR((*from_normal - Rc).norm(), 0, 1e-12);
  }
}

TEST(Orientation, TypedErrors) {
  EXPECT_EQ(tiltFromDown(Vec3::Zero()).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(tiltFromDown(Vec3(NAN, 0, 1)).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(fuseOrientation(Vec3(0, 1, 0), Vec3(0, 2, 0)).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(anglesFromWallNormal(Vec3(1, 0, 0)).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(downFromSpecificForce(Mat3::Identity(), Vec3(0, -1, 0)), Vec3(0, 1, 0));
}

}  // namespace
}  // namespace procam::keystone
