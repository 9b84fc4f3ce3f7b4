// The yaw/pitch/roll convention on the virtual rig (ARCHITECTURE.md, "Frames and
// conventions"): a scene file places a projector at known angles in front of a wall,
// and the simulator's true pose of that projector gives back the same signed angles
// through keystone::anglesFromRotation; its optical axis and its tilt sensor move the
// way the convention says. Scene and keystone use one definition, so every comparison
// is exact up to rounding (1e-9 rad).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/units.hpp"
#include "keystone/orientation.hpp"
#include "sim/scene.hpp"
#include "sim/sensors.hpp"

namespace procam::keystone {
namespace {

// A projector 1.2 m high at the origin, a wall y = 3 (the keystone wall frame: X to the
// right along the wall, Y into it, Z up) and an accelerometer mounted with the
// projector's axes.
Result<sim::Scene> rigAt(double yaw_deg, double pitch_deg, double roll_deg) {
  const std::string text = R"([scene]
name = "angles"
[[projectors]]
name = "proj"
resolution = [1280, 720]
intrinsics = { fx = 1400.0, fy = 1400.0, cx = 639.5, cy = 359.5 }
pose = { position = [0.0, 0.0, 1.2], yaw_deg = )" +
                           std::to_string(yaw_deg) + ", pitch_deg = " + std::to_string(pitch_deg) +
                           ", roll_deg = " + std::to_string(roll_deg) + R"( }
[[tilt_sensors]]
name = "accel"
attached_to = "proj"
[[surfaces]]
name = "wall"
type = "plane"
point = [0.0, 3.0, 0.0]
normal = [0.0, -1.0, 0.0]
)";
  return sim::Scene::parse(text, "angles.toml", {});
}

struct Truth {
  Mat3 R;       // wall frame -> projector
  Vec3 centre;  // world
  Vec3 axis;    // optical axis, world
  Vec3 right;   // image x, world
};

Truth truthOf(const sim::Scene& scene) {
  const geom::Pose& p = scene.at(0).projectors[0].model.pose;
  return {p.R, p.center(), p.R.row(2).transpose(), p.R.row(0).transpose()};
}

// Where the optical axis meets the wall y = 3.
Vec3 onTheWall(const Truth& t) {
  return t.centre + (3.0 - t.centre.y()) / t.axis.y() * t.axis;
}

TEST(RigAngles, TheSimulatorsPoseGivesBackTheScenesSignedAngles) {
  const double cases[][3] = {{20, 0, 0}, {-20, 0, 0}, {0, 15, 0},   {0, -15, 0},
                             {0, 0, 10}, {0, 0, -10}, {25, -12, 7}, {-35, 20, -15}};
  for (const auto& c : cases) {
    auto scene = rigAt(c[0], c[1], c[2]);
    ASSERT_TRUE(scene) << scene.error().message;
    const Angles a = anglesFromRotation(truthOf(*scene).R);
    EXPECT_NEAR(radToDeg(a.yaw), c[0], 1e-9) << c[0] << " " << c[1] << " " << c[2];
    EXPECT_NEAR(radToDeg(a.pitch), c[1], 1e-9) << c[0] << " " << c[1] << " " << c[2];
    EXPECT_NEAR(radToDeg(a.roll), c[2], 1e-9) << c[0] << " " << c[1] << " " << c[2];
  }
}

TEST(RigAngles, PositiveYawTurnsTheOpticalAxisToTheRight) {
  auto right = rigAt(20, 0, 0), left = rigAt(-20, 0, 0);
  ASSERT_TRUE(right && left);
  // World +X is to the right of a viewer behind the projector, facing the wall.
  EXPECT_NEAR(onTheWall(truthOf(*right)).x(), 3.0 * std::tan(degToRad(20)), 1e-12);
  EXPECT_NEAR(onTheWall(truthOf(*left)).x(), -3.0 * std::tan(degToRad(20)), 1e-12);
}

TEST(RigAngles, PositivePitchTiltsTheOpticalAxisUp) {
  auto up = rigAt(0, 15, 0), down = rigAt(0, -15, 0);
  ASSERT_TRUE(up && down);
  EXPECT_NEAR(onTheWall(truthOf(*up)).z(), 1.2 + 3.0 * std::tan(degToRad(15)), 1e-12);
  EXPECT_NEAR(onTheWall(truthOf(*down)).z(), 1.2 - 3.0 * std::tan(degToRad(15)), 1e-12);
}

TEST(RigAngles, PositiveRollLowersTheRightSideOfTheImage) {
  auto clockwise = rigAt(0, 0, 10), counter = rigAt(0, 0, -10);
  ASSERT_TRUE(clockwise && counter);
  EXPECT_NEAR(truthOf(*clockwise).right.z(), -std::sin(degToRad(10)), 1e-12);
  EXPECT_NEAR(truthOf(*counter).right.z(), std::sin(degToRad(10)), 1e-12);
}

TEST(RigAngles, TheTiltSensorSeesTheScenesPitchAndRoll) {
  const double cases[][2] = {{15, 0}, {-15, 0}, {0, 10}, {0, -10}, {-12, 7}};
  for (const auto& c : cases) {
    auto scene = rigAt(30, c[0], c[1]);  // yaw is invisible to gravity
    ASSERT_TRUE(scene) << scene.error().message;
    auto s = sim::sampleTilt(*scene, "accel", 0.0, 1, false);
    ASSERT_TRUE(s) << s.error().message;
    // Mount: sensor axes = projector axes.
    auto a = tiltFromDown(downFromSpecificForce(Mat3::Identity(), s->truth));
    ASSERT_TRUE(a) << a.error().message;
    EXPECT_NEAR(radToDeg(a->pitch), c[0], 1e-9) << c[0] << " " << c[1];
    EXPECT_NEAR(radToDeg(a->roll), c[1], 1e-9) << c[0] << " " << c[1];
  }
}

}  // namespace
}  // namespace procam::keystone
