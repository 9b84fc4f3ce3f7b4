#include "geometry/homography.hpp"

#include <Eigen/LU>
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

using detail::Similarity;
using Vec9 = Eigen::Matrix<double, 9, 1>;

// Shape measure of a triangle: twice its area over its longest edge squared
// (~ sine of the smallest angle); 0 for collinear or coincident corners.
double triangleShape(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double longest =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  if (!(longest > 0)) return 0;
  const Vec2 u = b - a, v = c - a;
  return std::abs(u.x() * v.y() - u.y() * v.x()) / longest;
}

// Below this shape measure three (normalised) points count as collinear.
constexpr double kCollinearShape = 1e-9;

bool anyThreeCollinear(const std::array<Vec2, 4>& p, double tol) {
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      for (int k = j + 1; k < 4; ++k) {
        if (triangleShape(p[i], p[j], p[k]) < tol) return true;
      }
    }
  }
  return false;
}

// Geometric degeneracy of one side (normalised points): fewer than four distinct
// points, all points on one line, or exactly four distinct points with three on a line.
// Near-degenerate configurations beyond these show up in the condition number.
Result<void> checkSide(const std::vector<Vec2>& pts, const char* side) {
  constexpr double kSame = 1e-12;  // normalised units (mean distance sqrt(2))
  std::vector<Vec2> distinct;
  for (const Vec2& p : pts) {
    bool seen = false;
    for (const Vec2& q : distinct) seen = seen || (p - q).norm() < kSame;
    if (!seen) distinct.push_back(p);
    if (distinct.size() > 4) break;
  }
  if (distinct.size() < 4) {
    return fail(ErrorCode::kDegenerate,
                std::string("homography: fewer than 4 distinct ") + side + " points");
  }
  if (distinct.size() == 4 &&
      anyThreeCollinear({distinct[0], distinct[1], distinct[2], distinct[3]}, kCollinearShape)) {
    return fail(ErrorCode::kDegenerate, std::string("homography: three of the four distinct ") +
                                            side + " points are collinear");
  }
  // Principal spreads (singular values of the centred points; the centroid is 0
  // after normalisation): the smaller one vanishes when all points are on a line.
  Eigen::MatrixXd centred(pts.size(), 2);
  for (std::size_t i = 0; i < pts.size(); ++i) centred.row(Eigen::Index(i)) = pts[i].transpose();
  const Eigen::VectorXd sv = detail::singularValues(centred);
  if (!(sv(1) > kCollinearShape * sv(0))) {
    return fail(ErrorCode::kDegenerate,
                std::string("homography: all ") + side + " points are collinear");
  }
  return {};
}

struct Normalized {
  Similarity<2> ts, td;
  std::vector<Vec2> s, d;
};

Result<Normalized> prepare(std::span<const Vec2> src, std::span<const Vec2> dst) {
  if (src.size() != dst.size()) {
    return fail(ErrorCode::kInvalidInput, "homography: src and dst differ in length");
  }
  if (src.size() < 4) {
    return fail(ErrorCode::kTooFewPoints, "homography: needs at least 4 correspondences");
  }
  if (!detail::allFiniteAndBounded<2>(src) || !detail::allFiniteAndBounded<2>(dst)) {
    return fail(ErrorCode::kInvalidInput, "homography: non-finite or huge coordinates");
  }
  auto ts = detail::hartley<2>(src);
  auto td = detail::hartley<2>(dst);
  if (!ts || !td) return fail(ErrorCode::kDegenerate, "homography: all points coincide");
  Normalized n{*ts, *td, {}, {}};
  n.s.reserve(src.size());
  n.d.reserve(dst.size());
  for (const Vec2& p : src) n.s.push_back(ts->apply(p));
  for (const Vec2& p : dst) n.d.push_back(td->apply(p));
  if (auto ok = checkSide(n.s, "source"); !ok) return tl::unexpected(ok.error());
  if (auto ok = checkSide(n.d, "destination"); !ok) return tl::unexpected(ok.error());
  return n;
}

struct Dlt {
  Mat3 Hn;  // in the normalised frames
  double condition;
};

// Null vector of the 2n x 9 DLT system (HZ Algorithm 4.2); condition is σ1/σ8.
Dlt solveDlt(const Normalized& n) {
  Eigen::MatrixXd A(2 * Eigen::Index(n.s.size()), 9);
  for (std::size_t i = 0; i < n.s.size(); ++i) {
    const double x = n.s[i].x(), y = n.s[i].y(), u = n.d[i].x(), v = n.d[i].y();
    const Eigen::Index r = 2 * Eigen::Index(i);
    A.row(r) << 0, 0, 0, -x, -y, -1, v * x, v * y, v;
    A.row(r + 1) << x, y, 1, 0, 0, 0, -u * x, -u * y, -u;
  }
  const detail::NullVector nv = detail::smallestRightSingularVector(A);
  const Eigen::VectorXd& h = nv.v;
  Dlt out;
  out.Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  out.condition = nv.singular(7) > 0 ? nv.singular(0) / nv.singular(7)
                                     : std::numeric_limits<double>::infinity();
  return out;
}

Mat3 denormalize(const Normalized& n, const Mat3& Hn) {
  return n.td.inverseMatrix() * Hn * n.ts.matrix();
}

// RMS transfer error in dst pixels; nullopt when a point maps to infinity.
std::optional<double> transferRms(const Mat3& H, std::span<const Vec2> src,
                                  std::span<const Vec2> dst) {
  double sum = 0;
  for (std::size_t i = 0; i < src.size(); ++i) {
    auto p = applyHomography(H, src[i]);
    if (!p) return std::nullopt;
    sum += (*p - dst[i]).squaredNorm();
  }
  const double rms = std::sqrt(sum / double(src.size()));
  if (!std::isfinite(rms)) return std::nullopt;
  return rms;
}

// Dst-side geometric error in the normalised frames (a uniform scaling of the pixel
// error, so its minimiser is the ML estimate). H = H0 + B·δ with B an orthonormal
// basis of the tangent space of ||H|| = const at H0: 8 parameters, no gauge freedom.
struct TransferError {
  const Normalized& n;
  Vec9 h0;
  Eigen::Matrix<double, 9, 8> B;  // fixed size: the per-point products stay inlined

  TransferError(const Normalized& norm, const Mat3& H0) : n(norm) {
    for (int r = 0; r < 3; ++r) h0.segment<3>(3 * r) = H0.row(r).transpose();
    h0.normalize();
    B = detail::orthogonalComplement(h0);
  }

  Mat3 matrixAt(const Eigen::VectorXd& delta) const {
    const Vec9 h = h0 + B * delta;
    Mat3 H;
    H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
    return H;
  }

  // Keeps w away from 0 so residuals stay finite; LM rejects such steps anyway.
  static double safeW(double w) {
    constexpr double kTiny = 1e-12;
    return std::abs(w) < kTiny ? (w < 0 ? -kTiny : kTiny) : w;
  }

  void residual(const Eigen::VectorXd& delta, Eigen::VectorXd& f) const {
    const Mat3 H = matrixAt(delta);
    for (std::size_t i = 0; i < n.s.size(); ++i) {
      const Vec3 q = H * n.s[i].homogeneous();
      const double w = safeW(q.z());
      f(2 * i) = q.x() / w - n.d[i].x();
      f(2 * i + 1) = q.y() / w - n.d[i].y();
    }
  }

  void jacobian(const Eigen::VectorXd& delta, Eigen::MatrixXd& J) const {
    const Mat3 H = matrixAt(delta);
    Eigen::Matrix<double, 2, 9> Jh;
    for (std::size_t i = 0; i < n.s.size(); ++i) {
      const Vec3 p = n.s[i].homogeneous();
      const Vec3 q = H * p;
      const double w = safeW(q.z());
      Jh.setZero();
      Jh.block<1, 3>(0, 0) = p.transpose() / w;
      Jh.block<1, 3>(0, 6) = -q.x() / (w * w) * p.transpose();
      Jh.block<1, 3>(1, 3) = p.transpose() / w;
      Jh.block<1, 3>(1, 6) = -q.y() / (w * w) * p.transpose();
      J.middleRows(2 * Eigen::Index(i), 2) = Jh * B;
    }
  }
};

Result<HomographyFit> finish(const Normalized& n, const Mat3& Hn, double condition, int iterations,
                             std::span<const Vec2> src, std::span<const Vec2> dst) {
  const Mat3 H = detail::canonicalCollineation(denormalize(n, Hn));
  if (!H.allFinite()) {
    return fail(ErrorCode::kIllConditioned, "homography: result not representable");
  }
  auto rms = transferRms(H, src, dst);
  if (!rms) {
    return fail(ErrorCode::kDegenerate,
                "homography: the fit maps a correspondence to infinity (inconsistent data)");
  }
  return HomographyFit{H, condition, *rms, iterations};
}

Result<double> checkedCondition(const Dlt& dlt, const HomographyOptions& options) {
  if (!(dlt.condition <= options.max_condition)) {
    return fail(ErrorCode::kIllConditioned,
                "homography: DLT condition number " + detail::shortNumber(dlt.condition) +
                    " exceeds the limit (points nearly collinear or clustered)");
  }
  return dlt.condition;
}

// LM from Hn0 in the normalised frames; keeps Hn0 if LM does not improve it.
std::pair<Mat3, int> refineNormalized(const Normalized& n, const Mat3& Hn0, int max_iterations) {
  const TransferError error(n, Hn0);
  detail::LeastSquaresProblem problem;
  problem.parameters = 8;
  problem.residuals = 2 * int(n.s.size());
  problem.residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& f) { error.residual(x, f); };
  problem.jacobian = [&](const Eigen::VectorXd& x, Eigen::MatrixXd& J) { error.jacobian(x, J); };
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(8);
  Eigen::VectorXd f0(problem.residuals), f1(problem.residuals);
  error.residual(delta, f0);
  const auto outcome = detail::runLevenbergMarquardt(problem, delta, max_iterations);
  error.residual(delta, f1);
  if (!delta.allFinite() || !(f1.squaredNorm() <= f0.squaredNorm())) {
    return {detail::unitFrobenius(Hn0), outcome.iterations};
  }
  return {error.matrixAt(delta), outcome.iterations};
}

}  // namespace

std::optional<Vec2> applyHomography(const Mat3& H, const Vec2& p) {
  const Vec3 q = H * p.homogeneous();
  if (!q.allFinite()) return std::nullopt;
  const double scale = std::max(std::abs(q.x()), std::abs(q.y()));
  if (q.z() == 0 || std::abs(q.z()) <= 1e-15 * scale) return std::nullopt;
  const Vec2 out(q.x() / q.z(), q.y() / q.z());
  if (!out.allFinite()) return std::nullopt;
  return out;
}

Result<Mat3> homographyFrom4(const std::array<Vec2, 4>& src, const std::array<Vec2, 4>& dst) {
  if (!detail::allFiniteAndBounded<2>(src) || !detail::allFiniteAndBounded<2>(dst)) {
    return fail(ErrorCode::kInvalidInput, "homography: non-finite or huge coordinates");
  }
  // Closed form: the projective basis {e1, e2, e3, (1,1,1)} is mapped to each quad
  // (M = [λ1 p1, λ2 p2, λ3 p3] with M·1 = p4), then H = M_dst · M_src⁻¹. Done in
  // Hartley-normalised coordinates for conditioning.
  auto basis = [](const std::array<Vec2, 4>& p, const Similarity<2>& T) -> std::optional<Mat3> {
    std::array<Vec2, 4> q;
    for (int i = 0; i < 4; ++i) q[i] = T.apply(p[i]);
    if (anyThreeCollinear(q, kCollinearShape)) return std::nullopt;
    Mat3 M;
    for (int i = 0; i < 3; ++i) M.col(i) = q[i].homogeneous();
    const Vec3 lambda = M.inverse() * q[3].homogeneous();  // M is well conditioned here
    return M * lambda.asDiagonal();
  };
  auto ts = detail::hartley<2>(src);
  auto td = detail::hartley<2>(dst);
  if (!ts || !td) return fail(ErrorCode::kDegenerate, "homography: all points coincide");
  const auto Ms = basis(src, *ts);
  const auto Md = basis(dst, *td);
  if (!Ms || !Md) {
    return fail(ErrorCode::kDegenerate, "homography: three of the four points are collinear");
  }
  const Mat3 Hn = *Md * Ms->inverse();
  const Mat3 H = detail::canonicalCollineation(td->inverseMatrix() * Hn * ts->matrix());
  if (!H.allFinite()) {
    return fail(ErrorCode::kIllConditioned, "homography: result not representable");
  }
  return H;
}

Result<HomographyFit> fitHomographyDlt(std::span<const Vec2> src, std::span<const Vec2> dst,
                                       const HomographyOptions& options) {
  auto n = prepare(src, dst);
  if (!n) return tl::unexpected(n.error());
  const Dlt dlt = solveDlt(*n);
  auto cond = checkedCondition(dlt, options);
  if (!cond) return tl::unexpected(cond.error());
  return finish(*n, dlt.Hn, *cond, 0, src, dst);
}

Result<HomographyFit> refineHomography(const Mat3& H0, std::span<const Vec2> src,
                                       std::span<const Vec2> dst,
                                       const HomographyOptions& options) {
  if (!H0.allFinite() || !(H0.cwiseAbs().maxCoeff() > 0)) {
    return fail(ErrorCode::kInvalidInput, "homography: initial matrix is zero or non-finite");
  }
  auto n = prepare(src, dst);
  if (!n) return tl::unexpected(n.error());
  auto cond = checkedCondition(solveDlt(*n), options);
  if (!cond) return tl::unexpected(cond.error());
  Mat3 Hn0 = n->td.matrix() * detail::unitFrobenius(H0) * n->ts.inverseMatrix();
  if (!Hn0.allFinite() || !(Hn0.cwiseAbs().maxCoeff() > 0)) {
    return fail(ErrorCode::kInvalidInput, "homography: initial matrix not representable");
  }
  Hn0 = detail::unitFrobenius(Hn0);
  if (!Hn0.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "homography: initial matrix not representable");
  }
  const auto [Hn, iterations] = refineNormalized(*n, Hn0, std::max(options.max_iterations, 1));
  return finish(*n, Hn, *cond, iterations, src, dst);
}

Result<HomographyFit> fitHomography(std::span<const Vec2> src, std::span<const Vec2> dst,
                                    const HomographyOptions& options) {
  auto n = prepare(src, dst);
  if (!n) return tl::unexpected(n.error());
  const Dlt dlt = solveDlt(*n);
  auto cond = checkedCondition(dlt, options);
  if (!cond) return tl::unexpected(cond.error());
  // Four points: the DLT is already exact; nothing to refine.
  if (!options.refine || src.size() == 4) return finish(*n, dlt.Hn, *cond, 0, src, dst);
  const auto [Hn, iterations] = refineNormalized(*n, dlt.Hn, std::max(options.max_iterations, 1));
  return finish(*n, Hn, *cond, iterations, src, dst);
}

}  // namespace procam::geom
