#include "keystone/wall_normal.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace procam::keystone {
namespace {

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

}  // namespace

Result<WallPlane> wallFromCorrespondences(const geom::Intrinsics& projector,
                                          const geom::Intrinsics& camera, const geom::Pose& pose,
                                          std::span<const Vec2> xp, std::span<const Vec2> xc,
                                          const WallPlaneOptions& options) {
  if (xp.size() != xc.size()) return fail(ErrorCode::kInvalidInput, "point lists differ in size");
  if (xp.size() < 3) return fail(ErrorCode::kTooFewPoints, "need >= 3 correspondences");
  const Mat3 Kp = projector.matrix(), Kc = camera.matrix();
  if (!Kp.allFinite() || !Kc.allFinite() || !pose.R.allFinite() || !pose.t.allFinite() ||
      Kp.determinant() == 0 || Kc.determinant() == 0)
    return fail(ErrorCode::kInvalidInput, "intrinsics or extrinsics not finite/invertible");
  const double baseline = pose.t.norm();
  if (baseline < 1e-9) return fail(ErrorCode::kDegenerate, "camera and projector share a centre");
  const Mat3 Kp_inv = Kp.inverse(), Kc_inv = Kc.inverse();
  const std::size_t n = xp.size();
  std::vector<Vec3> rays(n), obs(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!xp[i].allFinite() || !xc[i].allFinite())
      return fail(ErrorCode::kInvalidInput, "pixel is not finite");
    rays[i] = Kp_inv * xp[i].homogeneous();
    obs[i] = Kc_inv * xc[i].homogeneous();
    obs[i] /= obs[i].norm();
  }

  // Linear solve; the unknown m is scaled by the baseline for conditioning.
  const Vec3 t_unit = pose.t / baseline;
  Eigen::MatrixXd A(3 * n, 3);
  Eigen::VectorXd b(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Mat3 C = skew(obs[i]);
    A.block<3, 3>(3 * i, 0) = C * t_unit * rays[i].transpose();
    b.segment<3>(3 * i) = -C * pose.R * rays[i];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const auto& sv = svd.singularValues();
  WallPlane out;
  out.condition = sv(2) > 0 ? sv(0) / sv(2) : INFINITY;
  if (!(out.condition < options.max_condition))
    return fail(ErrorCode::kIllConditioned, "correspondences do not fix the wall plane");
  Vec3 m = svd.solve(b) / baseline;  // plane m·X = 1 in the projector frame

  // Gauss-Newton on the camera reprojection error (analytic in m via the chain rule).
  auto residuals = [&](const Vec3& mm, Eigen::VectorXd& r, Eigen::MatrixXd* J) -> bool {
    r.resize(2 * n);
    if (J) J->resize(2 * n, 3);
    for (std::size_t i = 0; i < n; ++i) {
      const double s = mm.dot(rays[i]);
      if (s <= 0) return false;
      const Vec3 X = rays[i] / s;
      const Vec3 q = Kc * (pose.R * X + pose.t);
      if (q.z() <= 0) return false;
      r.segment<2>(2 * i) = q.hnormalized() - xc[i];
      if (J) {
        Eigen::Matrix<double, 2, 3> dproj;
        dproj << 1 / q.z(), 0, -q.x() / (q.z() * q.z()), 0, 1 / q.z(), -q.y() / (q.z() * q.z());
        const Mat3 dX_dm = -rays[i] * rays[i].transpose() / (s * s);
        J->block<2, 3>(2 * i, 0) = dproj * Kc * pose.R * dX_dm;
      }
    }
    return true;
  };
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  if (!residuals(m, r, &J))
    return fail(ErrorCode::kDegenerate, "wall is not in front of both projector and camera");
  for (int it = 0; it < options.iterations; ++it) {
    const Vec3 step = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    if (!step.allFinite()) break;
    Eigen::VectorXd r_new;
    Eigen::MatrixXd J_new;
    if (!residuals(m + step, r_new, &J_new) || r_new.squaredNorm() > r.squaredNorm()) break;
    m += step;
    r = r_new;
    J = J_new;
    if (step.norm() < 1e-12 * m.norm()) break;
  }
  const double inv_d = m.norm();
  if (!std::isfinite(inv_d) || inv_d <= 0)
    return fail(ErrorCode::kDegenerate, "wall plane through the projector centre");
  out.normal = m / inv_d;
  out.distance = 1 / inv_d;
  out.rms = std::sqrt(r.squaredNorm() / double(n));
  return out;
}

}  // namespace procam::keystone
