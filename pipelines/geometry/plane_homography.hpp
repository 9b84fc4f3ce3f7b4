#pragma once
// An image's pixels on a planar display surface: the collineation between a
// device's pixels and 2D coordinates in an orthonormal basis of the plane
// ([Raskar02] §4.2.1: "the collineation A between the projector pixels and the
// points on the display screen"; §4.2.4 chains them). For a projector it is all
// that planar keystone and tiling need, with or without its intrinsics.
//
// Frames (ARCHITECTURE.md): world right-handed, metres, +Z up; pixels x right, y down.
#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"

namespace procam::geom {

// A 2D frame on a plane: the point (a, b) is origin + a u + b v (world). u and v
// are orthonormal, and u x v is the plane's normal on the lit (viewing) side.
struct PlaneBasis {
  Vec3 origin = Vec3::Zero();
  Vec3 u = Vec3::UnitX();
  Vec3 v = Vec3::UnitZ();

  Vec3 normal() const { return u.cross(v); }
  Vec3 toWorld(const Vec2& ab) const { return origin + ab.x() * u + ab.y() * v; }
  Vec2 toPlane(const Vec3& world) const {
    return {(world - origin).dot(u), (world - origin).dot(v)};
  }
};

// Pixel (x, y, 1) -> (a, b, 1) up to scale, in `basis`.
struct PlaneHomography {
  PlaneBasis basis;
  Mat3 H = Mat3::Identity();
};

// The upright basis of `plane` seen from `viewer` (a world point on its lit side):
// v is world up (+Z) projected into the plane, u points to the viewer's right, the
// origin is `origin` projected onto the plane. kDegenerate when the plane is
// (within 1e-6 rad) horizontal, so that no direction on it is up, or when `viewer`
// lies on the plane; kInvalidInput for non-finite input.
Result<PlaneBasis> uprightBasis(const Plane& plane, const Vec3& viewer, const Vec3& origin);

// The same plane point in two bases of one plane: (a, b, 1) in `from` -> (a', b', 1)
// in `to` (a rotation or reflection and a shift). kInvalidInput when the bases'
// planes differ by more than 1e-6 (normal or offset, metres).
Result<Mat3> changeOfBasis(const PlaneBasis& from, const PlaneBasis& to);

// Plane coordinates -> ideal (undistorted) pixels of a pinhole device seeing the
// plane: K [R u | R v | R origin + t] (HZ §8.1.1, a plane's image); its determinant
// is det K times the device centre's distance from the plane. kDegenerate when the
// centre lies within 1e-6 m of the plane (every pixel would see it edge-on).
Result<Mat3> planeToImage(const Intrinsics& K, const Pose& pose, const PlaneBasis& basis);

}  // namespace procam::geom
