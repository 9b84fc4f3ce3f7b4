#include "geometry/camera_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace procam::geom {
namespace {

bool finite(const Vec2& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

// Jacobian of Distortion::apply at a normalised point (2x2).
Eigen::Matrix2d distortionJacobian(const Distortion& d, const Vec2& p) {
  const double x = p.x(), y = p.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  // d(radial)/d(r2)
  const double dradial = d.k1 + r2 * (2 * d.k2 + 3 * r2 * d.k3);
  Eigen::Matrix2d J;
  J(0, 0) = radial + 2 * x * x * dradial + 2 * d.p1 * y + 6 * d.p2 * x;
  J(0, 1) = 2 * x * y * dradial + 2 * d.p1 * x + 2 * d.p2 * y;
  J(1, 0) = 2 * x * y * dradial + 2 * d.p1 * x + 2 * d.p2 * y;
  J(1, 1) = radial + 2 * y * y * dradial + 6 * d.p1 * y + 2 * d.p2 * x;
  return J;
}

bool validIntrinsics(const Intrinsics& K) {
  return std::isfinite(K.fx) && std::isfinite(K.fy) && std::isfinite(K.cx) && std::isfinite(K.cy) &&
         std::isfinite(K.skew) && K.fx != 0 && K.fy != 0;
}

// Pixel -> distorted normalised coordinates (inverse of the affine K).
Vec2 pixelToNormalized(const Intrinsics& K, const Vec2& pixel) {
  const double y = (pixel.y() - K.cy) / K.fy;
  const double x = (pixel.x() - K.cx - K.skew * y) / K.fx;
  return {x, y};
}

Vec2 normalizedToPixel(const Intrinsics& K, const Vec2& n) {
  return {K.fx * n.x() + K.skew * n.y() + K.cx, K.fy * n.y() + K.cy};
}

}  // namespace

Mat3 Intrinsics::matrix() const {
  Mat3 K;
  K << fx, skew, cx, 0, fy, cy, 0, 0, 1;
  return K;
}

Intrinsics Intrinsics::fromMatrix(const Mat3& K) {
  const double s = K(2, 2);
  Intrinsics out;
  out.fx = K(0, 0) / s;
  out.skew = K(0, 1) / s;
  out.cx = K(0, 2) / s;
  out.fy = K(1, 1) / s;
  out.cy = K(1, 2) / s;
  return out;
}

Vec2 Distortion::apply(const Vec2& p) const {
  const double x = p.x(), y = p.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

bool Distortion::radialMonotonicUpTo(double r2) const {
  // d/dr [r (1 + k1 r^2 + k2 r^4 + k3 r^6)] as a cubic in s = r^2; positive at s = 0. It
  // stays positive on [0, r2] when it is at r2 and at its turning points inside.
  const auto slope = [this](double s) { return 1 + s * (3 * k1 + s * (5 * k2 + s * 7 * k3)); };
  if (!(slope(r2) > 0)) return false;
  // Turning points: 21 k3 s^2 + 10 k2 s + 3 k1 = 0.
  const double a = 21 * k3, b = 10 * k2, c = 3 * k1;
  std::array<double, 2> roots = {-1, -1};
  if (a == 0) {
    if (b != 0) roots[0] = -c / b;
  } else if (const double disc = b * b - 4 * a * c; disc >= 0) {
    roots = {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)};
  }
  for (const double s : roots) {
    if (s > 0 && s < r2 && !(slope(s) > 0)) return false;
  }
  return true;
}

Result<Vec2> Distortion::remove(const Vec2& distorted) const {
  if (!finite(distorted)) return fail(ErrorCode::kInvalidInput, "undistort: non-finite point");
  if (isZero()) return distorted;
  // The physical inverse is the branch of apply⁻¹ through the origin (apply(0) = 0,
  // J(0) = I). Far from the centre the polynomial folds back and other roots appear,
  // so plain Newton from the distorted point can land on the wrong one. Continuation
  // follows the branch: solve apply(u) = s·distorted for s rising from 0 to 1, each
  // step started from the previous root, and require det J > 0 all the way; losing it
  // means the point lies beyond the fold, outside the model's valid field.
  // Intermediate roots only seed the next step; the last one is solved to rounding.
  const double scale = 1 + distorted.norm();
  Vec2 u = Vec2::Zero();
  double s = 0, step = 0.25;
  while (s < 1) {
    const double s_next = std::min(1.0, s + step);
    const Vec2 target = s_next * distorted;
    // Predictor: the previous root scaled along the ray.
    Vec2 v = s > 0 ? Vec2(u * (s_next / s)) : target;
    const double tol = (s_next < 1 ? 1e-10 : 1e-14) * scale;
    bool ok = false;
    for (int it = 0; it < 30; ++it) {
      const Vec2 r = apply(v) - target;
      const Eigen::Matrix2d J = distortionJacobian(*this, v);
      const double det = J.determinant();
      if (!(det > 0) || !r.allFinite()) break;
      if (r.norm() <= tol) {
        ok = true;
        break;
      }
      v -= J.inverse() * r;
    }
    if (ok && (v - u).norm() <= 0.5 * (u.norm() + target.norm() + 1e-3)) {
      u = v;
      s = s_next;
      step = std::min(0.25, 2 * step);
    } else if ((step *= 0.5) < 1e-6) {
      return fail(ErrorCode::kNoConvergence,
                  "undistort: point lies beyond the fold of the distortion model (outside its "
                  "valid field)");
    }
  }
  return u;
}

Pose Pose::inverse() const {
  Pose inv;
  inv.R = R.transpose();
  inv.t = -(R.transpose() * t);
  return inv;
}

Pose Pose::relativeTo(const Pose& other) const {
  Pose rel;
  rel.R = R * other.R.transpose();
  rel.t = t - rel.R * other.t;
  return rel;
}

Pose Pose::lookAt(const Vec3& eye, const Vec3& target, const Vec3& up) {
  Vec3 z = target - eye;
  if (!(z.norm() > 0) || !z.allFinite()) z = Vec3::UnitY();
  z.normalize();
  // y is -up with its component along z removed; if up is (anti)parallel to z or
  // unusable, take the world axis least aligned with z as the up hint.
  Vec3 up_hint = up;
  Vec3 y = -up_hint + up_hint.dot(z) * z;
  if (!(y.norm() > 1e-12 * std::max(1.0, up_hint.norm()))) {
    Eigen::Index axis = 0;
    z.cwiseAbs().minCoeff(&axis);
    up_hint = Vec3::Unit(axis);
    y = -up_hint + up_hint.dot(z) * z;
  }
  y.normalize();
  const Vec3 x = y.cross(z);
  Pose pose;
  pose.R.row(0) = x.transpose();
  pose.R.row(1) = y.transpose();
  pose.R.row(2) = z.transpose();
  pose.t = -(pose.R * eye);
  return pose;
}

Mat34 projectionMatrix(const Intrinsics& K, const Pose& pose) {
  Mat34 Rt;
  Rt.leftCols<3>() = pose.R;
  Rt.col(3) = pose.t;
  return K.matrix() * Rt;
}

std::optional<Vec2> projectWith(const Mat34& P, const Vec3& world) {
  const Vec3 h = P.leftCols<3>() * world + P.col(3);
  if (!h.allFinite()) return std::nullopt;
  // w ~ 0 relative to the image coordinates: the point is on the plane through the
  // optical centre parallel to the image (it maps to infinity).
  const double scale = std::max(std::abs(h.x()), std::abs(h.y()));
  if (std::abs(h.z()) <= 1e-15 * scale || h.z() == 0) return std::nullopt;
  const Vec2 p(h.x() / h.z(), h.y() / h.z());
  if (!finite(p)) return std::nullopt;
  return p;
}

Mat34 CameraModel::projectionMatrix() const {
  return geom::projectionMatrix(K, pose);
}

std::optional<Vec2> CameraModel::project(const Vec3& world) const {
  const Vec3 d = pose.toDevice(world);
  if (!d.allFinite() || !(d.z() > 0)) return std::nullopt;
  const Vec2 n(d.x() / d.z(), d.y() / d.z());
  // Past the lens model's fold the polynomial turns back and would put a point far off
  // the axis into the frame: no pixel images it.
  if (!dist.isZero() && !dist.radialMonotonicUpTo(n.squaredNorm())) return std::nullopt;
  const Vec2 p = normalizedToPixel(K, dist.isZero() ? n : dist.apply(n));
  if (!finite(p)) return std::nullopt;
  return p;
}

Result<Vec2> CameraModel::undistortPixel(const Vec2& pixel) const {
  if (!finite(pixel)) return fail(ErrorCode::kInvalidInput, "undistortPixel: non-finite pixel");
  if (!validIntrinsics(K)) return fail(ErrorCode::kInvalidInput, "undistortPixel: invalid K");
  auto n = dist.remove(pixelToNormalized(K, pixel));
  if (!n) return tl::unexpected(n.error());
  const Vec2 p = normalizedToPixel(K, *n);
  if (!finite(p)) return fail(ErrorCode::kNoConvergence, "undistortPixel: result not finite");
  return p;
}

Result<Ray> CameraModel::backproject(const Vec2& pixel) const {
  if (!finite(pixel)) return fail(ErrorCode::kInvalidInput, "backproject: non-finite pixel");
  if (!validIntrinsics(K)) return fail(ErrorCode::kInvalidInput, "backproject: invalid K");
  if (!pose.R.allFinite() || !pose.t.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "backproject: non-finite pose");
  }
  auto n = dist.remove(pixelToNormalized(K, pixel));
  if (!n) return tl::unexpected(n.error());
  const Vec3 dir_device = Vec3(n->x(), n->y(), 1.0).normalized();
  Ray ray;
  ray.origin = pose.center();
  ray.dir = (pose.R.transpose() * dir_device).normalized();
  if (!ray.dir.allFinite() || !ray.origin.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "backproject: ray not finite");
  }
  return ray;
}

bool CameraModel::inImage(const Vec2& p) const {
  return p.x() >= -0.5 && p.x() < width - 0.5 && p.y() >= -0.5 && p.y() < height - 0.5;
}

}  // namespace procam::geom
