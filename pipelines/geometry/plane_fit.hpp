#pragma once
// Planes: least-squares and RANSAC fits ([Raskar02] §4.1.1 coplanarity, §7.3 planar
// display surfaces).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::geom {

// n · x + d = 0 with |n| = 1.
struct Plane {
  Vec3 n = Vec3::UnitZ();
  double d = 0;
  double signedDistance(const Vec3& x) const { return n.dot(x) + d; }
};

struct PlaneFit {
  Plane plane;
  double rms = 0;                      // RMS distance of the inliers
  std::vector<std::uint32_t> inliers;  // indices (all points for least squares)
};

// The plane through `point_on_plane` with unit normal `n`, oriented the way every
// plane procamd writes is: the largest-magnitude component of n is positive.
Plane orientedPlane(Vec3 n, const Vec3& point_on_plane);

// The plane a x + b y + c z + d = 0 with its normal made unit length; nullopt when a
// coefficient is not finite or (a, b, c) is (nearly) zero.
std::optional<Plane> planeFromCoefficients(double a, double b, double c, double d);

// kDegenerate for coincident or collinear points (extent ratio < 1e-9 or within the
// rounding of the coordinates) and for isotropic sets with no unique best plane.
// n is oriented so that its largest-magnitude component is positive.
Result<PlaneFit> fitPlane(std::span<const Vec3> points);

struct RansacOptions {
  double threshold = 0.001;  // inlier distance, world units
  int iterations = 500;
  double confidence = 0.999;  // early stop
  std::uint64_t seed = 1;
};

// `plane` (normal made unit length) with the points within `threshold` of it as inliers
// and their RMS distance: a plane known beforehand, checked against new points.
PlaneFit planeInliers(std::span<const Vec3> points, const Plane& plane, double threshold);

// RANSAC on 3-point samples, then a least-squares refit on the inliers.
Result<PlaneFit> fitPlaneRansac(std::span<const Vec3> points, const RansacOptions& options = {});

}  // namespace procam::geom
