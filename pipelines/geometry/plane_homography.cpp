#include "geometry/plane_homography.hpp"

#include <cmath>

namespace procam::geom {

namespace {

// A plane within this of horizontal has no up direction worth the name: the
// projected +Z would be dominated by the normal's rounding.
constexpr double kMinUpComponent = 1e-6;
constexpr double kOnPlane = 1e-6;  // metres

bool finitePlane(const Plane& p) {
  return p.n.allFinite() && std::isfinite(p.d) && std::abs(p.n.norm() - 1) < 1e-9;
}

}  // namespace

Result<PlaneBasis> uprightBasis(const Plane& plane, const Vec3& viewer, const Vec3& origin) {
  if (!finitePlane(plane) || !viewer.allFinite() || !origin.allFinite())
    return fail(ErrorCode::kInvalidInput, "upright basis: non-finite plane or points");
  const double side = plane.signedDistance(viewer);
  if (std::abs(side) < kOnPlane)
    return fail(ErrorCode::kDegenerate, "upright basis: the viewer lies on the plane");
  const Vec3 n = side > 0 ? plane.n : Vec3(-plane.n);  // towards the viewer
  const Vec3 up = Vec3::UnitZ() - Vec3::UnitZ().dot(n) * n;
  if (up.norm() < kMinUpComponent)
    return fail(ErrorCode::kDegenerate,
                "the plane is horizontal: no direction on it is upright (world +Z up)");
  PlaneBasis b;
  b.v = up.normalized();
  b.u = b.v.cross(n);  // the viewer's right, looking along -n with +Z up
  b.origin = origin - plane.signedDistance(origin) * plane.n;
  return b;
}

Result<Mat3> changeOfBasis(const PlaneBasis& from, const PlaneBasis& to) {
  for (const PlaneBasis* b : {&from, &to}) {
    if (!b->origin.allFinite() || !b->u.allFinite() || !b->v.allFinite())
      return fail(ErrorCode::kInvalidInput, "plane basis is not finite");
  }
  const Vec3 n_from = from.normal(), n_to = to.normal();
  if (n_from.cross(n_to).norm() > 1e-6 || std::abs(n_to.dot(from.origin - to.origin)) > 1e-6)
    return fail(ErrorCode::kInvalidInput, "plane bases lie on different planes");
  Mat3 M = Mat3::Identity();
  M(0, 0) = from.u.dot(to.u);
  M(0, 1) = from.v.dot(to.u);
  M(1, 0) = from.u.dot(to.v);
  M(1, 1) = from.v.dot(to.v);
  M(0, 2) = (from.origin - to.origin).dot(to.u);
  M(1, 2) = (from.origin - to.origin).dot(to.v);
  return M;
}

Result<Mat3> planeToImage(const Intrinsics& K, const Pose& pose, const PlaneBasis& basis) {
  if (!K.matrix().allFinite() || !pose.R.allFinite() || !pose.t.allFinite() ||
      !basis.origin.allFinite() || !basis.u.allFinite() || !basis.v.allFinite())
    return fail(ErrorCode::kInvalidInput, "plane to image: non-finite input");
  if (std::abs(basis.normal().dot(pose.center() - basis.origin)) < kOnPlane)
    return fail(ErrorCode::kDegenerate, "the device lies on the plane");
  Mat3 M;
  M.col(0) = pose.R * basis.u;
  M.col(1) = pose.R * basis.v;
  M.col(2) = pose.toDevice(basis.origin);
  return Mat3(K.matrix() * M);
}

}  // namespace procam::geom
