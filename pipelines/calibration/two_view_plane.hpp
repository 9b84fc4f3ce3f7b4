#pragma once
// The display plane from points two calibrated cameras both see ([Raskar02] §4.1.1
// "Display Surface Estimation", reduced to a plane): the same projected features (the
// corners of one AprilTag frame) found in both images, triangulated from the two
// cameras' rays and fitted with a plane. It gives route (b′) ([Raskar02] §4.2.4) its
// plane when no one has measured the wall.
#include <optional>
#include <span>
#include <string>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"

namespace procam::calib {

// One projected feature seen by both cameras: its pixel in each image, as captured
// (distortion is removed through each camera's model).
struct TwoViewPoint {
  Vec2 a = Vec2::Zero(), b = Vec2::Zero();
};

struct TwoViewPlane {
  geom::PlaneFit fit;            // its inliers index the triangulated points
  std::size_t triangulated = 0;  // points whose rays met in front of both cameras
  double noise_m = 0;            // the points' depth noise, from the rays (metres)
};

// Rays that pass more than `max_gap` apart (metres), or more than five times the pairs'
// median miss distance, are a mismatch and are dropped; the
// plane is a RANSAC fit with five times the points' depth noise (at least 0.5 mm) as its
// threshold, refitted to its inliers. That noise comes from the rays: the median
// distance by which they miss each other over the median sine of the angle between them.
// kTooFewPoints below 8 triangulated points; kIllConditioned when the rays meet at
// under 2 degrees (median); kDegenerate when fewer than 90 % of them
// lie on the plane (the points are not one plane) or the points are collinear. `a` and
// `b` name the cameras in messages. `prior` (the plane other projectors of the wall
// were calibrated on) is returned, with the points' residuals, when 90 % of them lie
// within the threshold of it: every projector of one wall then maps onto one plane.
Result<TwoViewPlane> planeFromTwoViews(const geom::CameraModel& camera_a,
                                       const geom::CameraModel& camera_b,
                                       std::span<const TwoViewPoint> points, const std::string& a,
                                       const std::string& b,
                                       const std::optional<geom::Plane>& prior = {},
                                       double max_gap = 0.5);

}  // namespace procam::calib
