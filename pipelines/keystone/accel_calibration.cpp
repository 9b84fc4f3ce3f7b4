#include "keystone/accel_calibration.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <vector>

namespace procam::keystone {

Result<CalibrationFit> calibrateSixPosition(std::span<const Vec3> readings) {
  if (readings.size() < 6) return fail(ErrorCode::kTooFewPoints, "need >= 6 still readings");
  for (const Vec3& r : readings)
    if (!r.allFinite()) return fail(ErrorCode::kInvalidInput, "reading is not finite");

  // Start: for each axis the reading where it dominates most positively/negatively.
  Vec3 offset, scale;
  for (int a = 0; a < 3; ++a) {
    const Vec3* hi = nullptr;
    const Vec3* lo = nullptr;
    for (const Vec3& r : readings) {
      const double share = r(a) / r.norm();
      if (share > 0.7 && (!hi || r(a) > (*hi)(a))) hi = &r;
      if (share < -0.7 && (!lo || r(a) < (*lo)(a))) lo = &r;
    }
    if (!hi || !lo)
      return fail(ErrorCode::kDegenerate, std::string("no reading with axis ") + "xyz"[a] +
                                              " pointing " + (hi ? "down" : "up"));
    offset(a) = 0.5 * ((*hi)(a) + (*lo)(a));
    scale(a) = 0.5 * ((*hi)(a) - (*lo)(a));
  }

  // Gauss-Newton on r_k = |(raw_k - o) / s| - 1 over (o, s).
  const std::size_t n = readings.size();
  Eigen::Matrix<double, 6, 1> x;
  x << offset, scale;
  auto eval = [&](const Eigen::Matrix<double, 6, 1>& p, Eigen::VectorXd& r, Eigen::MatrixXd& J) {
    r.resize(n);
    J.resize(n, 6);
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 u = (readings[k] - p.head<3>()).cwiseQuotient(p.tail<3>());
      const double norm = u.norm();
      r(k) = norm - 1;
      for (int a = 0; a < 3; ++a) {
        const double du = u(a) / norm;        // d|u| / du_a
        J(k, a) = -du / p(3 + a);             // du_a / do_a = -1 / s_a
        J(k, 3 + a) = -du * u(a) / p(3 + a);  // du_a / ds_a = -u_a / s_a
      }
    }
  };
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  eval(x, r, J);
  bool converged = false;
  for (int it = 0; it < 50 && !converged; ++it) {
    const Eigen::Matrix<double, 6, 6> JtJ = J.transpose() * J;
    if (Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>>(JtJ).singularValues()(5) < 1e-12)
      return fail(ErrorCode::kDegenerate, "readings do not fix all six parameters");
    const Eigen::Matrix<double, 6, 1> step = JtJ.ldlt().solve(-J.transpose() * r);
    x += step;
    eval(x, r, J);
    converged = step.norm() < 1e-10;
  }
  if (!converged || !x.allFinite() || (x.tail<3>().array() <= 0).any())
    return fail(ErrorCode::kNoConvergence, "six-position calibration did not converge");
  CalibrationFit out;
  out.calibration.offset = x.head<3>();
  out.calibration.scale = x.tail<3>();
  out.rms = std::sqrt(r.squaredNorm() / double(n));
  return out;
}

}  // namespace procam::keystone
