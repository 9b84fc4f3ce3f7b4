#pragma once
// Triangulation from rays or from projection matrices ([Raskar02] §4.1.1, display surface
// estimation from a stereo pair).
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::geom {

struct RayRayPoint {
  Vec3 point;             // midpoint of the shortest segment between the rays
  double gap = 0;         // length of that segment
  double t1 = 0, t2 = 0;  // ray parameters of the closest points (> 0: in front)
};

// kDegenerate for (near-)parallel rays.
Result<RayRayPoint> triangulateRays(const Ray& a, const Ray& b);

// Linear (normalised DLT) triangulation from >= 2 views. kDegenerate when all
// back-projected rays are (nearly) parallel (sine < 1e-8: coincident centres, or a
// point at infinity) or the solution lies at infinity.
Result<Vec3> triangulateLinear(std::span<const Mat34> P, std::span<const Vec2> pixels);

}  // namespace procam::geom
