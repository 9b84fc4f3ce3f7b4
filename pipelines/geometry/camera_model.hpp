#pragma once
// Pinhole model shared by cameras and projectors ([Raskar02] §3.1.2, eq. 3.1): a projector
// is the dual of a camera, P = K[R|t]. Frames follow ARCHITECTURE.md: x right, y down,
// z forward; pixel centres at integer coordinates; R, t map world -> device.
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::geom {

struct Intrinsics {
  double fx = 1.0, fy = 1.0, cx = 0.0, cy = 0.0, skew = 0.0;

  Mat3 matrix() const;
  static Intrinsics fromMatrix(const Mat3& K);  // K is normalised so K(2,2) = 1
};

// OpenCV's radial-tangential model (k1, k2, p1, p2, k3) on normalised coordinates.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  bool isZero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
  Vec2 apply(const Vec2& normalized) const;
  // Whether the radial part r (1 + k1 r^2 + k2 r^4 + k3 r^6) still grows with r over
  // [0, sqrt(r2)]: beyond its first turning point (the fold) the model images nothing.
  bool radialMonotonicUpTo(double r2) const;
  // Inverse of apply() on the branch through the centre (Newton with continuation);
  // kNoConvergence for points beyond the model's fold (no physical preimage),
  // kInvalidInput for NaN/Inf.
  Result<Vec2> remove(const Vec2& distorted) const;
};

// Rigid world -> device transform: x_device = R * x_world + t.
struct Pose {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();

  Vec3 center() const { return -R.transpose() * t; }  // device origin in world
  Vec3 toDevice(const Vec3& world) const { return R * world + t; }
  Vec3 toWorld(const Vec3& device) const { return R.transpose() * (device - t); }
  Pose inverse() const;
  // This device's pose in the frame of the device posed by `other` (both world ->
  // device): x_this = R x_other + t.
  Pose relativeTo(const Pose& other) const;
  // Device at `eye` with its +z axis towards `target` and its -y axis as close to
  // `up` as possible (image y points down). Degenerate input never yields NaN: if
  // eye == target the device looks along world +Y; if up is parallel to the view
  // direction the world axis least aligned with it is used as up.
  static Pose lookAt(const Vec3& eye, const Vec3& target, const Vec3& up);
};

struct Ray {
  Vec3 origin = Vec3::Zero();
  Vec3 dir = Vec3::UnitZ();  // unit length
  Vec3 at(double t) const { return origin + t * dir; }
};

struct CameraModel {
  Intrinsics K;
  Distortion dist;
  Pose pose;
  int width = 0, height = 0;

  Mat34 projectionMatrix() const;  // K [R | t]; ignores distortion
  // World point -> pixel (with distortion). nullopt when the point is not in front
  // of the device (z <= 0 in the device frame).
  std::optional<Vec2> project(const Vec3& world) const;
  // Pixel -> world ray through the optical centre, distortion removed.
  Result<Ray> backproject(const Vec2& pixel) const;
  // Distorted pixel -> ideal (undistorted) pixel with the same K.
  Result<Vec2> undistortPixel(const Vec2& pixel) const;
  bool inImage(const Vec2& pixel) const;  // pixel centre inside [-0.5, w-0.5) x [-0.5, h-0.5)
};

Mat34 projectionMatrix(const Intrinsics& K, const Pose& pose);

// Homogeneous projection with a 3x4 matrix; nullopt when w is ~0 (point at infinity
// on the image plane's horizon).
std::optional<Vec2> projectWith(const Mat34& P, const Vec3& world);

}  // namespace procam::geom
