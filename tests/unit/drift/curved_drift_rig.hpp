#pragma once
// cylinder3 with its cameras at 1600x1200 (curved_drift_scene.hpp) as a drift check's rig:
// the truth at rest as the rig model, the TRUE wall as its mesh and the centre
// projector's pixels lighting it, for the drift tests on a curved surface.
#include <gtest/gtest.h>

#include <memory>
#include <optional>

#include "core/units.hpp"
#include "curved_drift_scene.hpp"
#include "drift/projector_camera_map.hpp"
#include "geometry/yaw_pitch_roll.hpp"
#include "sim/renderer.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"
#include "unit/common/cylinder_wall.hpp"

namespace procam::drift::testing_curved {

constexpr std::size_t kCentre = 1;  // proj_c
constexpr std::size_t kCamera = 0;  // cam_a

inline geom::Pose turned(const geom::Pose& pose, double yaw_deg, double pitch_deg) {
  geom::YawPitchRoll a;
  a.yaw = degToRad(yaw_deg);
  a.pitch = degToRad(pitch_deg);
  const Mat3 Q = geom::parentFromChild(a);  // as the scene's events turn devices
  return {Q.transpose() * pose.R, Q.transpose() * pose.t};
}

struct CurvedRig {
  sim::Scene scene;
  rig::RigModel model;
  std::shared_ptr<const geom::MeshIntersector> wall;
  LitSurface lit;  // the rig model's projector on the mesh
};

// `projector`: the one whose pixels `lit` gives (default the centre one).
inline CurvedRig restingRig(std::size_t projector_index = kCentre) {
  auto scene = sim::Scene::parse(testing_support::cylinderWithDriftCameras(), "cylinder3", {});
  EXPECT_TRUE(scene) << scene.error().message;
  auto model = sim::truthRig(*scene, 0.0);
  EXPECT_TRUE(model) << model.error().message;
  auto wall = geom::MeshIntersector::build(testing_support::cylinderWall());
  EXPECT_TRUE(wall) << wall.error().message;
  CurvedRig r{*scene, *model, std::make_shared<geom::MeshIntersector>(std::move(*wall)), {}};
  const geom::CameraModel projector = r.model.projectors.at(projector_index).model();
  r.lit.occluder = r.wall;
  r.lit.point = [projector, wall = r.wall](const Vec2& fb) -> std::optional<Vec3> {
    auto ray = projector.backproject(fb);
    auto hit = ray ? wall->intersect(*ray) : std::nullopt;
    return hit ? std::optional<Vec3>(hit->point) : std::nullopt;
  };
  return r;
}

// The largest distance, in the true projector's pixels, between a framebuffer pixel and
// where the true projector puts the wall point `model`'s pixel lights.
inline double againstTruth(const CurvedRig& rig, const geom::CameraModel& model,
                           const geom::CameraModel& truth) {
  double worst = 0;
  for (int y = 0; y < model.height; y += 40) {
    for (int x = 0; x < model.width; x += 40) {
      auto hit = rig.wall->intersect(*model.backproject({x, y}));
      EXPECT_TRUE(hit);
      if (!hit) return 1e9;
      worst = std::max(worst, (*truth.project(hit->point) - Vec2(x, y)).norm());
    }
  }
  return worst;
}

// cam_a's frame of `state` with the centre projector showing `centre` and the side ones
// `sides` (8-bit, the framebuffer's size).
inline Result<cv::Mat> centreSeen(const CurvedRig& rig, const sim::SceneState& state,
                                  const cv::Mat& centre, const cv::Mat& sides) {
  auto renderer = sim::Renderer::create(rig.scene, state,
                                        {{"proj_l", sides}, {"proj_c", centre}, {"proj_r", sides}});
  if (!renderer) return tl::unexpected(renderer.error());
  return renderer->renderCamera("cam_a");
}

}  // namespace procam::drift::testing_curved
