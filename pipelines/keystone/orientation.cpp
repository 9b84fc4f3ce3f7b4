#include "keystone/orientation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace procam::keystone {
namespace {

Result<Vec3> unitOrError(const Vec3& v, const char* what) {
  const double n = v.norm();
  if (!std::isfinite(n) || n < 1e-12)
    return fail(ErrorCode::kInvalidInput, std::string(what) + " must be a finite, non-zero vector");
  return Vec3(v / n);
}

}  // namespace

Vec3 downFromSpecificForce(const Mat3& mount, const Vec3& specific_force) {
  return -(mount * specific_force);
}

Result<Angles> tiltFromDown(const Vec3& down) {
  auto d = unitOrError(down, "gravity direction");
  if (!d) return tl::unexpected(d.error());
  Angles out;
  out.pitch = std::atan2(-d->z(), std::hypot(d->x(), d->y()));
  out.roll = std::atan2(d->x(), d->y());
  return out;
}

Result<Angles> anglesFromWallNormal(const Vec3& normal) {
  auto n = unitOrError(normal, "wall normal");
  if (!n) return tl::unexpected(n.error());
  Vec3 m = *n;
  if (m.z() < 0) m = -m;  // into the wall
  if (m.z() < 1e-9) return fail(ErrorCode::kDegenerate, "wall is parallel to the optical axis");
  // With roll = 0: normal = (-sin yaw, sin pitch cos yaw, cos pitch cos yaw).
  Angles out;
  out.yaw = std::asin(std::clamp(-m.x(), -1.0, 1.0));
  out.pitch = std::atan2(m.y(), m.z());
  return out;
}

Result<FusedOrientation> fuseOrientation(const Vec3& down, const Vec3& normal) {
  auto d = unitOrError(down, "gravity direction");
  if (!d) return tl::unexpected(d.error());
  auto n = unitOrError(normal, "wall normal");
  if (!n) return tl::unexpected(n.error());
  const Vec3 up = -*d;  // wall Z in the projector frame
  Vec3 into = *n;
  if (into.z() < 0) into = -into;              // wall Y points away from the projector
  Vec3 horizontal = into - into.dot(up) * up;  // drop the part gravity already fixes
  const double h = horizontal.norm();
  if (h < 1e-6) return fail(ErrorCode::kDegenerate, "wall normal is parallel to gravity");
  horizontal /= h;
  FusedOrientation out;
  out.R.col(0) = horizontal.cross(up);  // X = Y x Z
  out.R.col(1) = horizontal;
  out.R.col(2) = up;
  out.wall_tilt = std::asin(std::clamp(std::abs(into.dot(up)), 0.0, 1.0));
  return out;
}

Result<Mat3> rotationFromDown(const Vec3& down) {
  auto a = tiltFromDown(down);
  if (!a) return tl::unexpected(a.error());
  return rotationFromAngles(*a);
}

Result<Mat3> rotationFromWallNormal(const Vec3& normal) {
  auto a = anglesFromWallNormal(normal);
  if (!a) return tl::unexpected(a.error());
  return rotationFromAngles(*a);
}

}  // namespace procam::keystone
