#pragma once
// Ground-truth devices for calibration tests: a projector and a camera with known
// K, pose and distortion, and helpers that intersect projector rays with planes.
#include <random>

#include "geometry/camera_model.hpp"
#include "geometry/intersect.hpp"
#include "geometry/plane_fit.hpp"

namespace procam::testing {

inline geom::CameraModel projector1024() {
  geom::CameraModel p;
  p.width = 1024;
  p.height = 768;
  p.K = {1500.0, 1510.0, 515.0, 700.0, 0.0};  // lens shift: principal point low in the image
  p.pose = geom::Pose::lookAt(Vec3(0.1, -2.0, 0.3), Vec3(0.0, 0.0, 0.5), Vec3::UnitZ());
  return p;
}

// Square pixels, no skew, principal point centred horizontally (lens shift only
// vertical): the projector model route (b) can identify.
inline geom::CameraModel squarePixelProjector() {
  geom::CameraModel p = projector1024();
  p.K = {1500.0, 1500.0, 511.5, 700.0, 0.0};
  return p;
}

inline geom::CameraModel camera640() {
  geom::CameraModel c;
  c.width = 640;
  c.height = 480;
  c.K = {620.0, 622.0, 322.0, 236.0, 0.0};
  c.dist = {-0.12, 0.03, 0.0005, -0.0003, 0.0};
  c.pose = geom::Pose::lookAt(Vec3(-0.35, -1.9, 0.45), Vec3(0.0, 0.0, 0.45), Vec3::UnitZ());
  return c;
}

// Plane through `point` with unit normal `normal`.
inline geom::Plane planeThrough(const Vec3& point, const Vec3& normal) {
  geom::Plane p;
  p.n = normal.normalized();
  p.d = -p.n.dot(point);
  return p;
}

// Where the projector pixel lands on the plane, if in front.
inline std::optional<Vec3> litPoint(const geom::CameraModel& projector, const Vec2& pixel,
                                    const geom::Plane& plane) {
  auto ray = projector.backproject(pixel);
  if (!ray) return std::nullopt;
  auto hit = geom::intersectPlane(*ray, plane);
  if (!hit) return std::nullopt;
  return hit->point;
}

}  // namespace procam::testing
