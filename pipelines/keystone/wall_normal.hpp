#pragma once
// The wall's plane in the projector frame from projector-camera correspondences, the
// camera rigidly attached with calibrated extrinsics ([Raskar02] §6.2.2 azimuth from the
// camera, §6.3 self-correcting projector).
//
// A wall point on the projector ray p = Kp^-1 x_p is X = p / (m·p) for the plane
// m·X = 1 (m = n / d). The camera sees c ~ R X + t ~ R p + t (m·p): the plane-induced
// homography with known motion is linear in m, [c]x t p^T m = -[c]x R p, two equations
// per correspondence. The linear solution is refined by Gauss-Newton on the camera
// reprojection error (the ML estimate when the camera's pixels carry the noise).
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::keystone {

struct WallPlane {
  Vec3 normal = Vec3::UnitZ();  // unit, projector frame, pointing into the wall (z > 0)
  double distance = 0;          // along the normal, in the units of the extrinsic t
  double rms = 0;               // camera reprojection RMS, pixels
  double condition = 0;         // of the linear system (σ1/σ3)
};

struct WallPlaneOptions {
  int iterations = 20;
  double max_condition = 1e8;
};

// `camera_from_projector`: x_camera = R x_projector + t. Pixels are undistorted.
// kTooFewPoints (< 3), kInvalidInput (sizes, NaN), kDegenerate (no baseline, wall behind
// the projector), kIllConditioned (collinear projector points: the plane is not fixed).
Result<WallPlane> wallFromCorrespondences(const geom::Intrinsics& projector,
                                          const geom::Intrinsics& camera,
                                          const geom::Pose& camera_from_projector,
                                          std::span<const Vec2> projector_pixels,
                                          std::span<const Vec2> camera_pixels,
                                          const WallPlaneOptions& options = {});

}  // namespace procam::keystone
