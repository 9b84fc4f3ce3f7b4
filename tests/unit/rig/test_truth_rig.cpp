// procam-sim truth --rig-json: the scene's truth as a rig model a test can hand to
// procamd. The devices are the scene's exactly; the accelerometer's calibration is
// estimated from simulated holds, so it comes within the noise of the scene's bias.
#include <gtest/gtest.h>

#include "rig/rig_model.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"

namespace procam::sim {
namespace {

TEST(TruthRig, HandheldProjectorWithItsCalibratedAccelerometer) {
  auto scene = resolveScene("handheld");
  ASSERT_TRUE(scene);
  auto rig = truthRig(*scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  const SceneState state = scene->at(0);
  ASSERT_EQ(rig->projectors.size(), scene->projectors().size());
  const rig::RigProjector& p = rig->projectors[0];
  const geom::CameraModel& truth = state.projector(p.name)->model;
  EXPECT_EQ(p.output, p.name);
  EXPECT_EQ(p.K.fx, truth.K.fx);
  EXPECT_EQ(p.pose.R, truth.pose.R);
  ASSERT_TRUE(p.tilt);
  const TiltSensorSpec& t = scene->tiltSensors().front();
  EXPECT_EQ(p.tilt->sensor, t.name);
  EXPECT_EQ(p.tilt->sensor_from_projector, t.sensor_from_projector);
  // Offset: the scene's bias (mg) within 1 mg (10 s holds average the noise down).
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(p.tilt->calibration.offset[i] * 1e3, t.bias_mg[i], 1.0);
  // The camera beside the lens is mounted on the projector.
  ASSERT_EQ(rig->cameras.size(), 1u);
  EXPECT_EQ(rig->cameras[0].attached_to, p.name);
  EXPECT_EQ(rig->attachedCamera(p.name), &rig->cameras[0]);
  // Through JSON and back unchanged.
  auto back = rig::rigFromJson(rig::rigToJson(*rig), "truth");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(rig::rigToJson(*back), rig::rigToJson(*rig));
  EXPECT_EQ(back->cameras[0].attached_to, p.name);
}

TEST(TruthRig, PlanarWallGivesItsPlaneAndTheViewer) {
  auto scene = resolveScene("wall_oblique");
  ASSERT_TRUE(scene);
  auto rig = truthRig(*scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  ASSERT_TRUE(rig->surface.plane);
  // The wall is y = 3.
  EXPECT_NEAR(std::abs(rig->surface.plane->n.y()), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(rig->surface.plane->d), 3.0, 1e-9);
  ASSERT_TRUE(rig->viewer.position);
  EXPECT_EQ(*rig->viewer.position, scene->viewerPosition(0));
}

TEST(TruthRig, CurvedScreenHasNoPlane) {
  auto scene = resolveScene("dome3");
  ASSERT_TRUE(scene);
  auto rig = truthRig(*scene, 0.0);
  ASSERT_TRUE(rig) << rig.error().message;
  EXPECT_FALSE(rig->surface.plane);
  EXPECT_EQ(rig->projectors.size(), scene->projectors().size());
}

}  // namespace
}  // namespace procam::sim
