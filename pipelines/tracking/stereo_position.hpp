#pragma once
// LED positions from two (or more) calibrated cameras by triangulation, and the
// constellation's world pose from them through the rigid fit of [Raskar02] eq. 4.2.
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::tracking {

struct TriangulatedPoint {
  Vec3 point = Vec3::Zero();
  Mat3 covariance = Mat3::Zero();  // first order, isotropic pixel noise sigma
  double rms_px = 0;               // reprojection RMS over the views
};

// One LED seen in every camera (`pixels[i]` in cameras[i], distorted pixels).
// kTooFewPoints for < 2 views; kDegenerate as geom::triangulateLinear.
Result<TriangulatedPoint> triangulateLed(std::span<const geom::CameraModel> cameras,
                                         std::span<const Vec2> pixels, double pixel_sigma);

struct StereoConstellation {
  geom::Pose pose;               // constellation -> world
  Vec3 position = Vec3::Zero();  // constellation origin, world
  Mat3 covariance = Mat3::Zero();
  double rms_m = 0;  // RMS of the LED fit residuals
};

// World pose of the constellation from its triangulated LEDs (>= 3, non-collinear);
// the origin's covariance is that of the fit's translation (mean of LED covariances
// over n, to first order).
Result<StereoConstellation> fitConstellation(std::span<const Vec3> leds,
                                             std::span<const TriangulatedPoint> measured);

}  // namespace procam::tracking
