#include "geometry/triangulate.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

namespace procam::geom {
namespace {

// Rays closer to parallel than this (sine of the angle between them) have no
// meaningful closest point: depth error grows like 1/sin.
constexpr double kMinSinAngle = 1e-8;

// The homogeneous solution is a double null vector (all views on one line through
// the point, or coincident centres) when the second-smallest singular value is
// this small relative to the largest.
constexpr double kMinSingularRatio = 1e-10;

// Smallest |w| (relative to the largest coordinate of the normalised homogeneous
// solution) that still gives a finite point.
constexpr double kMinW = 1e-12;

}  // namespace

Result<RayRayPoint> triangulateRays(const Ray& a, const Ray& b) {
  if (!a.origin.allFinite() || !a.dir.allFinite() || !b.origin.allFinite() || !b.dir.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "ray is not finite");
  }
  const double la = a.dir.norm(), lb = b.dir.norm();
  if (!(la > 0) || !(lb > 0)) return fail(ErrorCode::kInvalidInput, "ray direction is zero");
  // Closest points from the normal equations in cross-product form:
  // t1 = ((ob - oa) x db) . n / |n|^2, t2 = ((ob - oa) x da) . n / |n|^2, n = da x db.
  const Vec3 n = a.dir.cross(b.dir);
  const double nn = n.squaredNorm();
  if (!(std::sqrt(nn) > kMinSinAngle * la * lb)) {
    return fail(ErrorCode::kDegenerate, "rays are (nearly) parallel");
  }
  const Vec3 w = b.origin - a.origin;
  RayRayPoint out;
  out.t1 = w.cross(b.dir).dot(n) / nn;
  out.t2 = w.cross(a.dir).dot(n) / nn;
  const Vec3 pa = a.at(out.t1);
  const Vec3 pb = b.at(out.t2);
  out.point = 0.5 * (pa + pb);
  out.gap = (pa - pb).norm();
  if (!out.point.allFinite() || !std::isfinite(out.gap)) {
    return fail(ErrorCode::kIllConditioned, "closest point of the rays is not finite");
  }
  return out;
}

Result<Vec3> triangulateLinear(std::span<const Mat34> P, std::span<const Vec2> pixels) {
  if (P.size() != pixels.size()) {
    return fail(ErrorCode::kInvalidInput, "need one pixel per projection matrix");
  }
  if (P.size() < 2) return fail(ErrorCode::kTooFewPoints, "triangulation needs at least 2 views");
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (!P[i].allFinite() || !pixels[i].allFinite()) {
      return fail(ErrorCode::kInvalidInput, "view " + std::to_string(i) + " is not finite");
    }
  }
  // World normalisation (Hartley): centre and scale on the finite camera centres so
  // that the four columns of the system have comparable size whatever the scene
  // units and offsets (a 1e4 offset would otherwise swamp the 4th column).
  Vec3 centroid = Vec3::Zero();
  std::vector<Vec3> centres;
  for (const Mat34& p : P) {
    // Finite centre C = -M^-1 p4 (P = [M | p4]); affine views (singular M) have none.
    const Eigen::FullPivLU<Mat3> lu(p.leftCols<3>());
    if (lu.rank() == 3) centres.push_back(-lu.solve(p.col(3)));
  }
  double scale = 1;
  if (!centres.empty()) {
    for (const Vec3& c : centres) centroid += c;
    centroid /= static_cast<double>(centres.size());
    double spread = 0;
    for (const Vec3& c : centres) spread += (c - centroid).norm();
    spread /= static_cast<double>(centres.size());
    if (spread > 0 && std::isfinite(spread)) scale = spread;
  }
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();  // X = T X'
  T.topLeftCorner<3, 3>() *= scale;
  T.topRightCorner<3, 1>() = centroid;
  // Two rows per view: x P3 - P1 and y P3 - P2, each scaled to unit norm so every
  // view weighs the same whatever its pixel scale.
  Eigen::MatrixXd A(2 * P.size(), 4);
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Eigen::Matrix<double, 3, 4> Pn = P[i] * T;
    const auto r = static_cast<Eigen::Index>(2 * i);
    A.row(r) = pixels[i].x() * Pn.row(2) - Pn.row(0);
    A.row(r + 1) = pixels[i].y() * Pn.row(2) - Pn.row(1);
    for (Eigen::Index k = r; k < r + 2; ++k) {
      const double len = A.row(k).norm();
      if (!(len > 0) || !std::isfinite(len)) {
        return fail(ErrorCode::kDegenerate, "view " + std::to_string(i) + " gives no constraint");
      }
      A.row(k) /= len;
    }
  }
  // The point is undetermined when all back-projected rays are parallel: they are
  // then one line (no parallax) or meet at infinity. A view's ray direction is the
  // intersection direction of its two constraint planes.
  Vec3 first = Vec3::Zero();
  double max_sin = 0;
  for (Eigen::Index r = 0; r < A.rows(); r += 2) {
    const Vec3 d = A.row(r).head<3>().transpose().cross(A.row(r + 1).head<3>().transpose());
    const double len = d.norm();
    if (!(len > 0))
      return fail(ErrorCode::kDegenerate, "a view's constraints do not meet in a ray");
    if (r == 0) {
      first = d / len;
    } else {
      max_sin = std::max(max_sin, first.cross(d / len).norm());
    }
  }
  if (!(max_sin > kMinSinAngle)) {
    return fail(ErrorCode::kDegenerate, "all rays are (nearly) parallel: no parallax");
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Vec4 s = svd.singularValues();
  if (!(s[2] > kMinSingularRatio * s[0])) {
    return fail(ErrorCode::kDegenerate, "views do not determine the point (rays coincide)");
  }
  const Vec4 Xn = svd.matrixV().col(3);
  if (!(std::abs(Xn[3]) > kMinW * Xn.head<3>().norm())) {
    return fail(ErrorCode::kDegenerate, "triangulated point is at infinity");
  }
  const Vec4 X = T * Xn;
  const Vec3 point = X.head<3>() / X[3];
  if (!point.allFinite()) return fail(ErrorCode::kIllConditioned, "point is not finite");
  return point;
}

}  // namespace procam::geom
