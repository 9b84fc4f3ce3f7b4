#include "geometry/plane_fit.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace procam::geom {
namespace {

// Second principal extent below this fraction of the first: the points lie on a
// line and any plane through it fits equally well.
constexpr double kCollinearRatio = 1e-9;
// Normal ambiguous when the two smallest extents coincide to this fraction of the
// largest (e.g. points spread isotropically in 3D around a line).
constexpr double kAmbiguousRatio = 1e-12;
// Multiple of the coordinate rounding below which an extent counts as zero.
constexpr double kRoundingFloor = 256;

Result<PlaneFit> fitSubset(std::span<const Vec3> points, std::vector<std::uint32_t> idx) {
  if (idx.size() < 3) return fail(ErrorCode::kTooFewPoints, "a plane needs at least 3 points");
  Vec3 centroid = Vec3::Zero();
  for (const std::uint32_t i : idx) centroid += points[i];
  centroid /= static_cast<double>(idx.size());
  // SVD of the centred points rather than eigen-decomposition of their covariance:
  // the smallest singular value is then resolved to rounding, not its square.
  Eigen::MatrixX3d c(static_cast<Eigen::Index>(idx.size()), 3);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    c.row(static_cast<Eigen::Index>(k)) = (points[idx[k]] - centroid).transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixX3d> svd(c, Eigen::ComputeFullV);
  const Vec3 s = svd.singularValues();
  // Extents within the rounding noise of the coordinates (~eps * |x| per point)
  // carry no shape information.
  double max_abs = 0;
  for (const std::uint32_t i : idx) max_abs = std::max(max_abs, points[i].cwiseAbs().maxCoeff());
  const double noise = kRoundingFloor * std::numeric_limits<double>::epsilon() * max_abs *
                       std::sqrt(static_cast<double>(idx.size()));
  if (!s.allFinite() || !(s[0] > noise)) {
    return fail(ErrorCode::kDegenerate, "points coincide");
  }
  if (!(s[1] > kCollinearRatio * s[0]) || !(s[1] > noise)) {
    return fail(ErrorCode::kDegenerate, "points are collinear");
  }
  if (!(s[1] - s[2] > kAmbiguousRatio * s[0])) {
    return fail(ErrorCode::kDegenerate, "no unique best plane (isotropic spread)");
  }
  PlaneFit fit;
  fit.plane = orientedPlane(svd.matrixV().col(2), centroid);
  double sum = 0;
  for (const std::uint32_t i : idx) sum += std::pow(fit.plane.signedDistance(points[i]), 2);
  fit.rms = std::sqrt(sum / static_cast<double>(idx.size()));
  if (!fit.plane.n.allFinite() || !std::isfinite(fit.plane.d) || !std::isfinite(fit.rms)) {
    return fail(ErrorCode::kIllConditioned, "plane fit is not finite");
  }
  fit.inliers = std::move(idx);
  return fit;
}

Result<void> checkPoints(std::span<const Vec3> points) {
  if (points.size() > std::numeric_limits<std::uint32_t>::max()) {
    return fail(ErrorCode::kInvalidInput, "too many points");
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      return fail(ErrorCode::kInvalidInput, "point " + std::to_string(i) + " is not finite");
    }
  }
  if (points.size() < 3) return fail(ErrorCode::kTooFewPoints, "a plane needs at least 3 points");
  return {};
}

// SplitMix64 and a multiply-shift range reduction: the same index sequence for a
// seed on every platform and standard library (std::uniform_int_distribution is not).
class IndexSampler {
 public:
  explicit IndexSampler(std::uint64_t seed) : state_(seed) {}
  std::uint32_t below(std::uint32_t n) {
    return static_cast<std::uint32_t>(((next() >> 32) * n) >> 32);
  }

 private:
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  std::uint64_t state_;
};

std::vector<std::uint32_t> inliersOf(std::span<const Vec3> points, const Vec3& n, double d,
                                     double threshold) {
  std::vector<std::uint32_t> in;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (std::abs(n.dot(points[i]) + d) <= threshold) in.push_back(static_cast<std::uint32_t>(i));
  }
  return in;
}

}  // namespace

Plane orientedPlane(Vec3 n, const Vec3& point_on_plane) {
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  if (n[k] < 0) n = -n;
  return Plane{n, -n.dot(point_on_plane)};
}

std::optional<Plane> planeFromCoefficients(double a, double b, double c, double d) {
  const Vec3 n(a, b, c);
  const double norm = n.norm();
  if (!n.allFinite() || !std::isfinite(d) || !(norm > 1e-9)) return std::nullopt;
  return Plane{n / norm, d / norm};
}

Result<PlaneFit> fitPlane(std::span<const Vec3> points) {
  if (auto ok = checkPoints(points); !ok) return tl::unexpected(ok.error());
  std::vector<std::uint32_t> all(points.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  return fitSubset(points, std::move(all));
}

PlaneFit planeInliers(std::span<const Vec3> points, const Plane& plane, double threshold) {
  PlaneFit out;
  const double norm = plane.n.norm();
  out.plane = norm > 0 ? Plane{plane.n / norm, plane.d / norm} : plane;
  double sum = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double r = out.plane.signedDistance(points[i]);
    if (!(std::abs(r) <= threshold)) continue;
    out.inliers.push_back(static_cast<std::uint32_t>(i));
    sum += r * r;
  }
  out.rms = out.inliers.empty() ? 0 : std::sqrt(sum / double(out.inliers.size()));
  return out;
}

Result<PlaneFit> fitPlaneRansac(std::span<const Vec3> points, const RansacOptions& options) {
  if (auto ok = checkPoints(points); !ok) return tl::unexpected(ok.error());
  if (!(options.threshold > 0) || !std::isfinite(options.threshold) || options.iterations < 1 ||
      !(options.confidence > 0 && options.confidence < 1)) {
    return fail(ErrorCode::kInvalidInput, "RANSAC options out of range");
  }
  const auto n = static_cast<std::uint32_t>(points.size());
  IndexSampler rng(options.seed);
  std::size_t best_count = 0;
  Vec3 best_n = Vec3::Zero();
  double best_d = 0;
  long long needed = options.iterations;
  for (long long it = 0; it < needed; ++it) {
    const std::uint32_t i = rng.below(n);
    std::uint32_t j = rng.below(n - 1);
    if (j >= i) ++j;
    std::uint32_t k = rng.below(n - 2);  // distinct from i and j
    if (k >= std::min(i, j)) ++k;
    if (k >= std::max(i, j)) ++k;
    const Vec3 e1 = points[j] - points[i];
    const Vec3 e2 = points[k] - points[i];
    const Vec3 normal = e1.cross(e2);
    const double len = normal.norm();
    if (!(len > kCollinearRatio * e1.norm() * e2.norm())) continue;  // collinear sample
    const Vec3 unit = normal / len;
    const double d = -unit.dot(points[i]);
    std::size_t count = 0;
    for (const Vec3& p : points) count += std::abs(unit.dot(p) + d) <= options.threshold;
    if (count <= best_count) continue;
    best_count = count;
    best_n = unit;
    best_d = d;
    // Early stop: iterations after which an all-inlier sample has been drawn with
    // the requested confidence, for the inlier ratio seen so far.
    const double w3 = std::pow(static_cast<double>(count) / n, 3);
    const double required =
        w3 >= 1 ? 0 : std::ceil(std::log1p(-options.confidence) / std::log1p(-w3));
    if (std::isfinite(required)) {
      needed = std::min<long long>(options.iterations,
                                   std::max<long long>(it + 1, static_cast<long long>(required)));
    }
  }
  if (best_count < 3)
    return fail(ErrorCode::kDegenerate, "no plane through 3 non-collinear points");
  // Least-squares refit on the consensus set, then re-select inliers with the refit
  // plane (a few rounds, until the set stops changing).
  std::vector<std::uint32_t> inliers = inliersOf(points, best_n, best_d, options.threshold);
  Result<PlaneFit> fit = fitSubset(points, inliers);
  for (int round = 0; round < 3 && fit; ++round) {
    std::vector<std::uint32_t> again =
        inliersOf(points, fit->plane.n, fit->plane.d, options.threshold);
    if (again == fit->inliers || again.size() < 3) break;
    Result<PlaneFit> refit = fitSubset(points, std::move(again));
    if (!refit) break;
    fit = std::move(refit);
  }
  return fit;
}

}  // namespace procam::geom
