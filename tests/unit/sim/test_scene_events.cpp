// Scene events ([[events]]): a projector or camera bumped, a wall moved, at a given time,
// as the drift tests of a running daemon need them.
#include <gtest/gtest.h>

#include <cmath>

#include "core/units.hpp"
#include "sim/renderer.hpp"
#include "sim/scene.hpp"

namespace procam::sim {
namespace {

std::string eventScene(const std::string& events) {
  return R"([scene]
name = "bumps"

[[projectors]]
name = "proj"
resolution = [640, 400]
intrinsics = { fx = 800.0, fy = 800.0, cx = 319.5, cy = 199.5 }
pose = { position = [0.0, 0.0, 1.2], look_at = [0.0, 3.0, 1.2] }

[[cameras]]
name = "cam"
resolution = [640, 480]
intrinsics = { fx = 600.0, fy = 600.0, cx = 319.5, cy = 239.5 }
pose = { position = [0.5, 0.0, 1.2], look_at = [0.0, 3.0, 1.2] }

[[cameras]]
name = "onboard"
resolution = [320, 240]
intrinsics = { fx = 300.0, fy = 300.0, cx = 159.5, cy = 119.5 }
attached_to = "proj"
offset = { position = [0.05, 0.0, 0.0] }

[[surfaces]]
name = "wall"
type = "plane"
point = [0.0, 3.0, 0.0]
normal = [0.0, -1.0, 0.0]
)" + events;
}

double angleDeg(const Vec3& a, const Vec3& b) {
  return radToDeg(std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
}

Vec3 axis(const geom::CameraModel& m) {
  return m.pose.R.row(2).transpose();
}  // optical, world

TEST(SceneEvents, DevicesTurnAndTheWallMovesAtTheirTimes) {
  auto scene = Scene::parse(eventScene(R"(
[[events]]
t = 3.0
target = "wall"
move_m = [0.0, 0.01, 0.0]

[[events]]
t = 1.0
target = "proj"
rotate_deg = [0.5, 0.0, 0.0]

[[events]]
t = 2.0
target = "cam"
rotate_deg = [0.0, 0.3, 0.0]
move_m = [0.0, 0.0, 0.002]
)"),
                            "bumps.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->events().size(), 3u);
  EXPECT_EQ(scene->events()[0].name, "proj");  // in time order
  const SceneState before = scene->at(0.9), turned = scene->at(1.5), bumped = scene->at(2.5),
                   moved = scene->at(3.5);
  const auto& p0 = before.projector("proj")->model;
  const auto& p1 = turned.projector("proj")->model;
  // The projector turned 0.5 deg to its right about its own centre.
  EXPECT_NEAR(angleDeg(axis(p0), axis(p1)), 0.5, 1e-9);
  EXPECT_GT(axis(p1).x(), 1e-3);  // looking along +y, right is +x
  EXPECT_LT((p1.pose.center() - p0.pose.center()).norm(), 1e-12);
  // The camera on it turned with it, rigidly; the fixed camera did not.
  const auto& o0 = before.camera("onboard")->model;
  const auto& o1 = turned.camera("onboard")->model;
  EXPECT_LT((o1.pose.R * p1.pose.R.transpose() - o0.pose.R * p0.pose.R.transpose()).norm(), 1e-12);
  EXPECT_NEAR(angleDeg(axis(o0), axis(o1)), 0.5, 1e-9);
  EXPECT_EQ(turned.camera("cam")->model.pose.R, before.camera("cam")->model.pose.R);
  // The camera tilted up 0.3 deg and rose 2 mm.
  const auto& c1 = turned.camera("cam")->model;
  const auto& c2 = bumped.camera("cam")->model;
  EXPECT_NEAR(angleDeg(axis(c1), axis(c2)), 0.3, 1e-9);
  EXPECT_GT(axis(c2).z(), axis(c1).z());
  EXPECT_NEAR((c2.pose.center() - c1.pose.center()).z(), 0.002, 1e-12);
  // The wall: 1 cm farther once moved, and only in the states after the event.
  const geom::Ray ahead{Vec3(0, 0, 1.2), Vec3::UnitY()};
  ASSERT_TRUE(bumped.world && moved.world);
  EXPECT_NEAR(bumped.world->intersect(ahead)->hit.point.y(), 3.0, 1e-12);
  EXPECT_NEAR(moved.world->intersect(ahead)->hit.point.y(), 3.01, 1e-12);
  EXPECT_NEAR(scene->world().intersect(ahead)->hit.point.y(), 3.0, 1e-12);
  EXPECT_TRUE(moved.world->occluded({Vec3(0, 0, 1.2), Vec3::UnitY()}, 3.005 + 0.01));
  EXPECT_FALSE(moved.world->occluded({Vec3(0, 0, 1.2), Vec3::UnitY()}, 3.005));
  // What a camera sees follows: its pixels meet the wall where it stands at that time.
  for (const SceneState* state : {&bumped, &moved}) {
    auto r = Renderer::create(*scene, *state, {});
    ASSERT_TRUE(r) << r.error().message;
    const PixelTruth seen = r->truthAt(state->camera("cam")->model, Vec2(319.5, 239.5));
    ASSERT_TRUE(seen.hit);
    EXPECT_NEAR(seen.point.y(), state == &moved ? 3.01 : 3.0, 1e-9);
  }
}

TEST(SceneEvents, AZoomedProjectorScalesItsFocalLengthsFromItsTime) {
  auto scene = Scene::parse(eventScene(R"(
[[events]]
t = 1.0
target = "proj"
zoom = 1.03
)"),
                            "zoom.toml", {});
  ASSERT_TRUE(scene) << scene.error().message;
  const SceneState before = scene->at(0.9), after = scene->at(1.1);
  const auto& k0 = before.projector("proj")->model;
  const auto& k1 = after.projector("proj")->model;
  EXPECT_NEAR(k1.K.fx, 1.03 * k0.K.fx, 1e-9);
  EXPECT_NEAR(k1.K.fy, 1.03 * k0.K.fy, 1e-9);
  EXPECT_EQ(k1.K.cx, k0.K.cx);
  EXPECT_EQ(k1.K.cy, k0.K.cy);
  EXPECT_EQ(k1.pose.R, k0.pose.R);  // only the lens changed
  EXPECT_EQ(k1.pose.t, k0.pose.t);
}

TEST(SceneEvents, EventsThatNameNothingOrDoNothingAreRefused) {
  for (const auto& [events, key] : std::vector<std::pair<std::string, std::string>>{
           {"[[events]]\nt = 1.0\ntarget = \"nobody\"\nmove_m = [0.0, 0.0, 0.1]\n", "target"},
           {"[[events]]\nt = 1.0\ntarget = \"proj\"\n", "rotate_deg, move_m or zoom"},
           {"[[events]]\nt = 1.0\ntarget = \"cam\"\nzoom = 1.02\n", "zoom"},
           {"[[events]]\nt = 1.0\ntarget = \"proj\"\nzoom = 3.0\n", "zoom"},
           {"[[events]]\nt = 1.0\ntarget = \"wall\"\nrotate_deg = [1.0, 0.0, 0.0]\n", "rotate_deg"},
           {"[[events]]\nt = 1.0\ntarget = \"proj\"\nrotate_deg = [200.0, 0.0, 0.0]\n",
            "rotate_deg"},
           {"[[events]]\nt = -1.0\ntarget = \"proj\"\nmove_m = [0.0, 0.0, 0.1]\n", "t"},
           {"[[events]]\ntarget = \"proj\"\nmove_m = [0.0, 0.0, 0.1]\n", "t"},
           {"[[events]]\nt = 1.0\ntarget = \"proj\"\nmove_m = [0.0, 0.0, 0.1]\nspin = 3\n", "spin"},
           // A camera that shares the wall's name: the event's target is ambiguous.
           {"[[cameras]]\nname = \"wall\"\nresolution = [64, 48]\n"
            "intrinsics = { fx = 60.0, fy = 60.0, cx = 31.5, cy = 23.5 }\n"
            "pose = { position = [0.0, 0.0, 1.0], look_at = [0.0, 3.0, 1.0] }\n"
            "[[events]]\nt = 1.0\ntarget = \"wall\"\nmove_m = [0.0, 0.01, 0.0]\n",
            "more than one"}}) {
    auto scene = Scene::parse(eventScene(events), "bad.toml", {});
    ASSERT_FALSE(scene) << events;
    EXPECT_EQ(scene.error().code, ErrorCode::kParse);
    EXPECT_NE(scene.error().message.find(key), std::string::npos) << scene.error().message;
  }
}

}  // namespace
}  // namespace procam::sim
