#pragma once
// Internal to pipelines/geometry: Hartley normalisation (isotropic scaling, HZ §4.4.4)
// shared by the DLT estimators. Points are translated to their centroid and scaled so
// the mean distance from it is sqrt(dim); estimation then happens in that frame.
// Also the input bounds and scale helpers those estimators share.
#include <cmath>
#include <cstdio>
#include <span>
#include <string>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::geom::detail {

// Coordinates beyond this magnitude are rejected as kInvalidInput: squared terms of
// the DLT would overflow long before such values could carry pixel information.
inline constexpr double kMaxCoordinate = 1e100;

template <int D>
struct Similarity {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Hom = Eigen::Matrix<double, D + 1, D + 1>;
  Vec centroid = Vec::Zero();
  double scale = 1;  // normalised = scale * (x - centroid)

  Vec apply(const Vec& x) const { return scale * (x - centroid); }
  Hom matrix() const {
    Hom T = Hom::Identity();
    T.template topLeftCorner<D, D>() *= scale;
    T.template topRightCorner<D, 1>() = -scale * centroid;
    return T;
  }
  Hom inverseMatrix() const {
    Hom T = Hom::Identity();
    T.template topLeftCorner<D, D>() /= scale;
    T.template topRightCorner<D, 1>() = centroid;
    return T;
  }
};

template <int D>
bool allFiniteAndBounded(std::span<const Eigen::Matrix<double, D, 1>> points) {
  for (const auto& p : points) {
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kMaxCoordinate) return false;
  }
  return true;
}

// kDegenerate when all points coincide. Expects finite, bounded input.
template <int D>
Result<Similarity<D>> hartley(std::span<const Eigen::Matrix<double, D, 1>> points) {
  using Vec = Eigen::Matrix<double, D, 1>;
  Similarity<D> T;
  if (points.empty()) return fail(ErrorCode::kTooFewPoints, "normalisation: no points");
  // Running mean: no overflow for large coordinates.
  Vec c = Vec::Zero();
  double k = 0;
  for (const auto& p : points) {
    k += 1;
    c += (p - c) / k;
  }
  double mean_dist = 0;
  k = 0;
  for (const auto& p : points) {
    k += 1;
    mean_dist += ((p - c).norm() - mean_dist) / k;  // |p - c| <= 2e100: no overflow
  }
  const double scale = std::sqrt(double(D)) / mean_dist;
  // All points (numerically) equal: no frame to normalise into. Relative to the
  // coordinates' magnitude only, so the test is invariant to the units.
  if (!(mean_dist > 1e-14 * c.cwiseAbs().maxCoeff()) || !(scale < HUGE_VAL)) {
    return fail(ErrorCode::kDegenerate, "all points coincide");
  }
  T.centroid = c;
  T.scale = scale;
  return T;
}

// Short form of a number for error messages (e.g. "3.2e+09", "0.00012").
inline std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// M / ||M||_F without overflow or underflow in the norm for any finite, non-zero M.
template <class Matrix>
Matrix unitFrobenius(const Matrix& M) {
  const Matrix scaled = M / M.cwiseAbs().maxCoeff();
  return scaled / scaled.norm();
}

// The representative of a collineation's class with unit Frobenius norm and H(2,2) >= 0,
// so that results compare entry by entry; a non-finite or zero H is returned as it is
// (the caller checks finiteness).
inline Mat3 canonicalCollineation(const Mat3& H) {
  if (!H.allFinite() || !(H.cwiseAbs().maxCoeff() > 0)) return H;
  const Mat3 out = unitFrobenius(H);
  return out(2, 2) < 0 ? Mat3(-out) : out;
}

}  // namespace procam::geom::detail
