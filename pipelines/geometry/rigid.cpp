#include "geometry/rigid.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <string>

namespace procam::geom {
namespace {

// Umeyama works on the cross-covariance, whose singular values are the squared
// extents of the sets: the rotation about the long axis of a thin set is known only
// to ~eps / ratio^2. Sets thinner than this ratio of their two largest principal
// extents (1e-10 on the covariance, i.e. rotation error <~ 1e-6) count as collinear.
constexpr double kCollinearRatio = 1e-5;
constexpr double kRoundingFloor = 256;

Eigen::Matrix3Xd toMatrix(std::span<const Vec3> pts) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = pts[i];
  return m;
}

// Singular values of the centred set; the set spans a plane or more when the
// second one is neither negligible against the first nor within the rounding noise
// of the coordinates (~eps * |x| per point: a "width" of that size is no width).
bool spansPlane(const Eigen::Matrix3Xd& m) {
  const Eigen::Matrix3Xd c = m.colwise() - m.rowwise().mean();
  const Vec3 s = Eigen::JacobiSVD<Eigen::Matrix3Xd>(c).singularValues();
  const double noise = kRoundingFloor * std::numeric_limits<double>::epsilon() *
                       m.cwiseAbs().maxCoeff() * std::sqrt(static_cast<double>(m.cols()));
  return s[0] > noise && s[1] > kCollinearRatio * s[0] && s[1] > noise;
}

}  // namespace

Result<RigidFit> fitRigidTransform(std::span<const Vec3> from, std::span<const Vec3> to,
                                   bool with_scale) {
  if (from.size() != to.size()) {
    return fail(ErrorCode::kInvalidInput, "point sets differ in size (" +
                                              std::to_string(from.size()) + " vs " +
                                              std::to_string(to.size()) + ")");
  }
  if (from.size() < 3) {
    return fail(ErrorCode::kTooFewPoints, "a rigid transform needs at least 3 point pairs");
  }
  for (std::size_t i = 0; i < from.size(); ++i) {
    if (!from[i].allFinite() || !to[i].allFinite()) {
      return fail(ErrorCode::kInvalidInput, "point pair " + std::to_string(i) + " is not finite");
    }
  }
  const Eigen::Matrix3Xd src = toMatrix(from);
  const Eigen::Matrix3Xd dst = toMatrix(to);
  // Umeyama needs rank(cross-covariance) >= 2 for a unique rotation ([Raskar02] eq. 4.2):
  // both sets must span at least a plane.
  if (!spansPlane(src) || !spansPlane(dst)) {
    return fail(ErrorCode::kDegenerate, "points are collinear or coincident");
  }
  const Mat4 T = Eigen::umeyama(src, dst, with_scale);
  RigidFit fit;
  fit.scale = with_scale ? T.block<3, 3>(0, 0).col(0).norm() : 1.0;
  fit.R = T.block<3, 3>(0, 0) / fit.scale;
  fit.t = T.block<3, 1>(0, 3);
  if (!T.allFinite() || !(fit.scale > 0)) {
    return fail(ErrorCode::kIllConditioned, "rigid transform is not finite");
  }
  const Eigen::Matrix3Xd residual = (fit.scale * fit.R * src).colwise() + fit.t - dst;
  fit.rms = std::sqrt(residual.colwise().squaredNorm().mean());
  if (!std::isfinite(fit.rms)) {
    return fail(ErrorCode::kIllConditioned, "residual of the rigid transform is not finite");
  }
  return fit;
}

}  // namespace procam::geom
