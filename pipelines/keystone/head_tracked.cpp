#include "keystone/head_tracked.hpp"

#include <cmath>

namespace procam::keystone {
namespace {

bool validRect(const DisplayRect& S) {
  return S.corner.allFinite() && S.u.allFinite() && S.v.allFinite() && std::isfinite(S.width) &&
         std::isfinite(S.height) && S.width > 0 && S.height > 0 &&
         std::abs(S.u.norm() - 1) < 1e-9 && std::abs(S.v.norm() - 1) < 1e-9 &&
         std::abs(S.u.dot(S.v)) < 1e-9;
}

// NDC of S's frustum (x, y in [-1, 1] across S) -> world point on S, as a 4x3 matrix
// acting on (x, y, 1).
Eigen::Matrix<double, 4, 3> ndcToPlane(const DisplayRect& S) {
  Eigen::Matrix<double, 4, 3> M = Eigen::Matrix<double, 4, 3>::Zero();
  M.block<3, 1>(0, 0) = 0.5 * S.width * S.u;
  M.block<3, 1>(0, 1) = 0.5 * S.height * S.v;
  M.block<3, 1>(0, 2) = S.center();
  M(3, 2) = 1;
  return M;
}

}  // namespace

Vec2 ndcToPixel(const Vec2& ndc, int width, int height) {
  return {0.5 * (ndc.x() + 1) * width - 0.5, 0.5 * (1 - ndc.y()) * height - 0.5};
}

Vec2 pixelToNdc(const Vec2& pixel, int width, int height) {
  return {(2 * pixel.x() + 1) / width - 1, 1 - (2 * pixel.y() + 1) / height};
}

Result<DisplayRect> boundingDisplayRect(const Mat34& P, int width, int height, const Vec3& origin,
                                        const Vec3& u, const Vec3& v) {
  if (!P.allFinite() || width <= 0 || height <= 0 || !origin.allFinite() || !u.allFinite() ||
      !v.allFinite() || u.norm() == 0 || v.norm() == 0)
    return fail(ErrorCode::kInvalidInput, "bad projection matrix, size or plane axes");
  const Vec3 uu = u.normalized();
  const Vec3 vv = (v - v.dot(uu) * uu).normalized();
  if (!vv.allFinite()) return fail(ErrorCode::kDegenerate, "plane axes are parallel");
  const Vec3 n = uu.cross(vv);
  const Mat3 M = P.leftCols<3>();
  if (std::abs(M.determinant()) < 1e-300) return fail(ErrorCode::kDegenerate, "P has no centre");
  const Mat3 Minv = M.inverse();
  const Vec3 centre = -Minv * P.col(3);
  double lo_u = 1e300, hi_u = -1e300, lo_v = 1e300, hi_v = -1e300;
  const double w = width, h = height;
  const Vec2 corners[4] = {{-0.5, -0.5}, {w - 0.5, -0.5}, {w - 0.5, h - 0.5}, {-0.5, h - 0.5}};
  for (const Vec2& c : corners) {
    Vec3 d = Minv * c.homogeneous();
    // Orient the ray forwards: P maps points in front to positive w.
    if ((P * (centre + d).homogeneous()).z() < 0) d = -d;
    const double denom = n.dot(d);
    const double t = n.dot(origin - centre) / denom;
    if (!std::isfinite(t) || t <= 0 || std::abs(denom) < 1e-12 * d.norm())
      return fail(ErrorCode::kDegenerate, "projector corner ray misses the display plane");
    const Vec3 X = centre + t * d - origin;
    lo_u = std::min(lo_u, X.dot(uu));
    hi_u = std::max(hi_u, X.dot(uu));
    lo_v = std::min(lo_v, X.dot(vv));
    hi_v = std::max(hi_v, X.dot(vv));
  }
  DisplayRect S;
  S.u = uu;
  S.v = vv;
  S.corner = origin + lo_u * uu + lo_v * vv;
  S.width = hi_u - lo_u;
  S.height = hi_v - lo_v;
  return S;
}

Result<Mat4> offAxisProjection(const Vec3& eye, const DisplayRect& S, double near, double far) {
  if (!eye.allFinite() || !validRect(S))
    return fail(ErrorCode::kInvalidInput, "eye not finite or S not an orthonormal rectangle");
  if (!(near > 0 && far > near && std::isfinite(far)))
    return fail(ErrorCode::kInvalidInput, "need 0 < near < far");
  const Vec3 w = S.u.cross(S.v);
  const Vec3 rel = S.corner - eye;
  const double D = -w.dot(rel);  // eye distance to the plane
  if (!(D > 1e-12)) return fail(ErrorCode::kDegenerate, "eye is not in front of S");
  Mat4 view = Mat4::Identity();
  view.block<1, 3>(0, 0) = S.u.transpose();
  view.block<1, 3>(1, 0) = S.v.transpose();
  view.block<1, 3>(2, 0) = w.transpose();
  view.block<3, 1>(0, 3) = -view.block<3, 3>(0, 0) * eye;
  // Frustum edges on the near plane (glFrustum's l, r, b, t).
  const double l = S.u.dot(rel) * near / D, r = l + S.width * near / D;
  const double b = S.v.dot(rel) * near / D, t = b + S.height * near / D;
  Mat4 F = Mat4::Zero();
  F(0, 0) = 2 * near / (r - l);
  F(0, 2) = (r + l) / (r - l);
  F(1, 1) = 2 * near / (t - b);
  F(1, 2) = (t + b) / (t - b);
  F(2, 2) = -(far + near) / (far - near);
  F(2, 3) = -2 * far * near / (far - near);
  F(3, 2) = -1;
  return Mat4(F * view);
}

Result<Mat3> planeCollineation(const Mat34& P, int width, int height, const DisplayRect& S) {
  if (!P.allFinite() || width <= 0 || height <= 0 || !validRect(S))
    return fail(ErrorCode::kInvalidInput, "bad projection matrix, size or rectangle");
  Mat3 pixel_to_ndc;
  pixel_to_ndc << 2.0 / width, 0, 1.0 / width - 1, 0, -2.0 / height, 1 - 1.0 / height, 0, 0, 1;
  Mat3 A = pixel_to_ndc * (P * ndcToPlane(S));
  if (!A.allFinite() || std::abs(A(2, 2)) < 1e-12 * A.norm())
    return fail(ErrorCode::kDegenerate, "centre of S maps to infinity in the projector");
  A /= A(2, 2);
  return A;
}

Result<Mat4> singlePassMatrix(const Mat3& A) {
  if (!A.allFinite()) return fail(ErrorCode::kInvalidInput, "collineation is not finite");
  const Mat3 a = A / A(2, 2);
  const double c = 1 - std::abs(a(2, 0)) - std::abs(a(2, 1));
  if (!(c > 0))
    return fail(ErrorCode::kIllConditioned, "|a31| + |a32| >= 1: depth cannot be kept in [-1, 1]");
  Mat4 M = Mat4::Zero();
  M(0, 0) = a(0, 0), M(0, 1) = a(0, 1), M(0, 3) = a(0, 2);
  M(1, 0) = a(1, 0), M(1, 1) = a(1, 1), M(1, 3) = a(1, 2);
  M(2, 2) = c;
  M(3, 0) = a(2, 0), M(3, 1) = a(2, 1), M(3, 3) = 1;
  return M;
}

Result<HeadTrackedPath> headTrackedPath(const Vec3& eye, const DisplayRect& S, double near,
                                        double far, const Mat34& P, int width, int height) {
  HeadTrackedPath out;
  auto PT = offAxisProjection(eye, S, near, far);
  if (!PT) return tl::unexpected(PT.error());
  auto A = planeCollineation(P, width, height, S);
  if (!A) return tl::unexpected(A.error());
  auto A4 = singlePassMatrix(*A);
  if (!A4) return tl::unexpected(A4.error());
  out.P_T = *PT;
  out.A = *A;
  out.single_pass = *A4 * *PT;
  return out;
}

}  // namespace procam::keystone
