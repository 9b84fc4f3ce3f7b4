#include "geometry/projection_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "geometry/decompositions.hpp"
#include "geometry/levenberg_marquardt.hpp"
#include "geometry/normalization.hpp"

namespace procam::geom {
namespace {

using Vec12 = Eigen::Matrix<double, 12, 1>;

struct NormalizedCorrespondences {
  detail::Similarity<3> tw;
  detail::Similarity<2> tp;
  std::vector<Vec3> X;
  std::vector<Vec2> x;
};

Mat34 fromVector(const Vec12& p) {
  Mat34 P;
  P << p(0), p(1), p(2), p(3), p(4), p(5), p(6), p(7), p(8), p(9), p(10), p(11);
  return P;
}

Vec12 toVector(const Mat34& P) {
  Vec12 p;
  for (int r = 0; r < 3; ++r) p.segment<4>(4 * r) = P.row(r).transpose();
  return p;
}

Result<NormalizedCorrespondences> prepare(std::span<const Vec3> world, std::span<const Vec2> pixels,
                                          const ProjectionOptions& options) {
  if (world.size() != pixels.size()) {
    return fail(ErrorCode::kInvalidInput, "projection matrix: point lists differ in length");
  }
  if (world.size() < 6) {
    return fail(ErrorCode::kTooFewPoints, "projection matrix: needs at least 6 3D-2D pairs");
  }
  if (!detail::allFiniteAndBounded<3>(world) || !detail::allFiniteAndBounded<2>(pixels)) {
    return fail(ErrorCode::kInvalidInput, "projection matrix: non-finite or huge coordinates");
  }
  auto tw = detail::hartley<3>(world);
  auto tp = detail::hartley<2>(pixels);
  if (!tw || !tp) return fail(ErrorCode::kDegenerate, "projection matrix: all points coincide");
  NormalizedCorrespondences n{*tw, *tp, {}, {}};
  for (const Vec3& X : world) n.X.push_back(tw->apply(X));
  for (const Vec2& x : pixels) n.x.push_back(tp->apply(x));

  // Six distinct 3D points are the minimum for the 11 degrees of freedom.
  std::vector<Vec3> distinct;
  for (const Vec3& X : n.X) {
    bool seen = false;
    for (const Vec3& Y : distinct) seen = seen || (X - Y).norm() < 1e-12;
    if (!seen) distinct.push_back(X);
    if (distinct.size() >= 6) break;
  }
  if (distinct.size() < 6) {
    return fail(ErrorCode::kDegenerate, "projection matrix: fewer than 6 distinct 3D points");
  }
  // Principal spreads of the 3D points (centroid is 0 after normalisation). Points on
  // one plane leave P undetermined up to a family ([Raskar02] §4.1.1): the fix is geometric.
  Eigen::MatrixXd centred(n.X.size(), 3);
  for (std::size_t i = 0; i < n.X.size(); ++i) centred.row(Eigen::Index(i)) = n.X[i].transpose();
  const Eigen::VectorXd spreads = detail::singularValues(centred);
  const double ratio = spreads(2) / spreads(0);
  if (!(ratio >= options.coplanar_ratio)) {
    return fail(ErrorCode::kCoplanar,
                "projection matrix: the 3D points are (nearly) coplanar (thickness/extent = " +
                    detail::shortNumber(ratio) +
                    "), so depth and focal length cannot be separated; add points on a "
                    "non-planar surface, e.g. a second wall at an angle ([Raskar02] §4.1.1)");
  }
  // Image points all on one line: the camera centre lies in the points' plane or the
  // points are collinear; either way nothing is determined.
  Eigen::MatrixXd centred2(n.x.size(), 2);
  for (std::size_t i = 0; i < n.x.size(); ++i) centred2.row(Eigen::Index(i)) = n.x[i].transpose();
  const Eigen::VectorXd spreads2 = detail::singularValues(centred2);
  if (!(spreads2(1) > 1e-9 * spreads2(0))) {
    return fail(ErrorCode::kDegenerate, "projection matrix: all image points are collinear");
  }
  return n;
}

struct CameraDlt {
  Mat34 Pn;
  double condition;
};

// Null vector of the 2n x 12 DLT system (HZ §7.1); condition is σ1/σ11.
CameraDlt solveCameraDlt(const NormalizedCorrespondences& n) {
  Eigen::MatrixXd A(2 * Eigen::Index(n.X.size()), 12);
  for (std::size_t i = 0; i < n.X.size(); ++i) {
    const Vec4 X = n.X[i].homogeneous();
    const double u = n.x[i].x(), v = n.x[i].y();
    const Eigen::Index r = 2 * Eigen::Index(i);
    A.row(r) << Eigen::RowVector4d::Zero(), -X.transpose(), v * X.transpose();
    A.row(r + 1) << X.transpose(), Eigen::RowVector4d::Zero(), -u * X.transpose();
  }
  const detail::NullVector nv = detail::smallestRightSingularVector(A);
  CameraDlt out;
  out.Pn = fromVector(Vec12(nv.v));
  out.condition = nv.singular(10) > 0 ? nv.singular(0) / nv.singular(10)
                                      : std::numeric_limits<double>::infinity();
  return out;
}

// Reprojection error in the normalised image frame (a uniform scaling of the pixel
// error). P = P0 + B·δ with B spanning the tangent space of ||P|| = const: 11 parameters.
struct ReprojectionError {
  const NormalizedCorrespondences& n;
  Vec12 p0;
  Eigen::Matrix<double, 12, 11> B;  // fixed size: the per-point products stay inlined

  ReprojectionError(const NormalizedCorrespondences& norm, const Mat34& P0) : n(norm) {
    p0 = toVector(P0).normalized();
    B = detail::orthogonalComplement(p0);
  }

  Mat34 matrixAt(const Eigen::VectorXd& delta) const { return fromVector(p0 + B * delta); }

  static double safeW(double w) {
    constexpr double kTiny = 1e-12;
    return std::abs(w) < kTiny ? (w < 0 ? -kTiny : kTiny) : w;
  }

  void residual(const Eigen::VectorXd& delta, Eigen::VectorXd& f) const {
    const Mat34 P = matrixAt(delta);
    for (std::size_t i = 0; i < n.X.size(); ++i) {
      const Vec3 q = P * n.X[i].homogeneous();
      const double w = safeW(q.z());
      f(2 * i) = q.x() / w - n.x[i].x();
      f(2 * i + 1) = q.y() / w - n.x[i].y();
    }
  }

  void jacobian(const Eigen::VectorXd& delta, Eigen::MatrixXd& J) const {
    const Mat34 P = matrixAt(delta);
    Eigen::Matrix<double, 2, 12> Jp;
    for (std::size_t i = 0; i < n.X.size(); ++i) {
      const Vec4 X = n.X[i].homogeneous();
      const Vec3 q = P * X;
      const double w = safeW(q.z());
      Jp.setZero();
      Jp.block<1, 4>(0, 0) = X.transpose() / w;
      Jp.block<1, 4>(0, 8) = -q.x() / (w * w) * X.transpose();
      Jp.block<1, 4>(1, 4) = X.transpose() / w;
      Jp.block<1, 4>(1, 8) = -q.y() / (w * w) * X.transpose();
      J.middleRows(2 * Eigen::Index(i), 2) = Jp * B;
    }
  }
};

std::pair<Mat34, int> refine(const NormalizedCorrespondences& n, const Mat34& Pn0,
                             int max_iterations) {
  const ReprojectionError error(n, Pn0);
  detail::LeastSquaresProblem problem;
  problem.parameters = 11;
  problem.residuals = 2 * int(n.X.size());
  problem.residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& f) { error.residual(x, f); };
  problem.jacobian = [&](const Eigen::VectorXd& x, Eigen::MatrixXd& J) { error.jacobian(x, J); };
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(11);
  Eigen::VectorXd f0(problem.residuals), f1(problem.residuals);
  error.residual(delta, f0);
  const auto outcome = detail::runLevenbergMarquardt(problem, delta, max_iterations);
  error.residual(delta, f1);
  if (!delta.allFinite() || !(f1.squaredNorm() <= f0.squaredNorm())) {
    return {detail::unitFrobenius(Pn0), outcome.iterations};
  }
  return {error.matrixAt(delta), outcome.iterations};
}

}  // namespace

Result<ProjectionFit> fitProjectionMatrix(std::span<const Vec3> world, std::span<const Vec2> pixels,
                                          const ProjectionOptions& options) {
  auto n = prepare(world, pixels, options);
  if (!n) return tl::unexpected(n.error());
  const CameraDlt dlt = solveCameraDlt(*n);
  if (!(dlt.condition <= options.max_condition)) {
    return fail(ErrorCode::kIllConditioned, "projection matrix: DLT condition number " +
                                                detail::shortNumber(dlt.condition) +
                                                " exceeds the limit (near-degenerate points)");
  }
  Mat34 Pn = dlt.Pn;
  int iterations = 0;
  if (options.refine) {
    std::tie(Pn, iterations) = refine(*n, Pn, std::max(options.max_iterations, 1));
  }
  Mat34 P = detail::unitFrobenius(Mat34(n->tp.inverseMatrix() * Pn * n->tw.matrix()));
  // Sign: the fitted points must lie in front of the device (w > 0).
  int in_front = 0;
  for (const Vec3& X : world) in_front += (P * X.homogeneous()).z() > 0 ? 1 : -1;
  if (in_front < 0) P = -P;

  double sum = 0;
  for (std::size_t i = 0; i < world.size(); ++i) {
    const Vec3 q = P * world[i].homogeneous();
    if (!(std::abs(q.z()) > 0)) {
      return fail(ErrorCode::kDegenerate,
                  "projection matrix: a point lies on the fitted camera's principal plane");
    }
    sum += (q.hnormalized() - pixels[i]).squaredNorm();
  }
  const double rms = std::sqrt(sum / double(world.size()));
  if (!P.allFinite() || !std::isfinite(rms)) {
    return fail(ErrorCode::kIllConditioned, "projection matrix: result not representable");
  }
  return ProjectionFit{P, dlt.condition, rms, iterations};
}

Result<KRt> decomposeProjectionMatrix(const Mat34& P_in) {
  if (!P_in.allFinite() || !(P_in.cwiseAbs().maxCoeff() > 0)) {
    return fail(ErrorCode::kInvalidInput, "decompose: P is zero or non-finite");
  }
  const Mat34 P = detail::unitFrobenius(P_in);
  Mat3 M = P.leftCols<3>();
  const double det = M.determinant();
  // A finite camera needs an invertible left 3x3 block (HZ §6.2.4). Measured by the
  // Hadamard ratio |det M| / Π‖row‖ (1 for orthogonal rows), invariant to the scale of
  // P and to the translation, unlike det M itself.
  const double hadamard = M.row(0).norm() * M.row(1).norm() * M.row(2).norm();
  if (!(std::abs(det) > 1e-10 * hadamard)) {
    return fail(ErrorCode::kDegenerate,
                "decompose: left 3x3 block is singular (camera at infinity or rank-deficient P)");
  }
  // P is defined up to scale λ; with M = λ K R, det K > 0 and det R = +1 the sign of λ is
  // the sign of det M. Dividing it out gives det R = +1 and puts scene points in front.
  const double lambda_sign = det > 0 ? 1.0 : -1.0;
  M *= lambda_sign;
  const Vec3 p4 = lambda_sign * P.col(3);

  // RQ via QR of the row-reversed transpose: (E M)ᵀ = Q U  =>  M = (E Uᵀ E)(E Qᵀ).
  Mat3 E = Mat3::Zero();
  E(0, 2) = E(1, 1) = E(2, 0) = 1;
  Eigen::MatrixXd Qd, Ud;
  detail::householderQr((E * M).transpose(), Qd, Ud);
  const Mat3 U = Ud, Q = Qd;
  Mat3 K = E * U.transpose() * E;
  Mat3 R = E * Q.transpose();
  // Make the diagonal of K positive: K D, D R with D = diag(±1), D² = I.
  const Vec3 d = K.diagonal().unaryExpr([](double v) { return v < 0 ? -1.0 : 1.0; });
  K = K * d.asDiagonal();
  R = d.asDiagonal() * R;
  if (R.determinant() < 0) {
    return fail(ErrorCode::kDegenerate, "decompose: inconsistent handedness");
  }
  const Vec3 t = K.triangularView<Eigen::Upper>().solve(p4);
  KRt out;
  out.K = Intrinsics::fromMatrix(K);
  out.pose.R = R;
  out.pose.t = t;
  if (!K.allFinite() || !R.allFinite() || !t.allFinite() || !(out.K.fx > 0) || !(out.K.fy > 0) ||
      !std::isfinite(out.K.cx) || !std::isfinite(out.K.cy)) {
    return fail(ErrorCode::kIllConditioned, "decompose: result not representable");
  }
  return out;
}

}  // namespace procam::geom
