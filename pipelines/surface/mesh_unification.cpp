#include "surface/mesh_unification.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "geometry/intersect.hpp"

namespace procam::surface {
namespace {

// Distance (projector pixels) from each cell of a projector's frame to the nearest cell
// its mesh does not cover; the frame's outside counts as not covered.
struct Coverage {
  cv::Mat distance;  // CV_32FC1, in cells
  int scale = 4;
  double at(const Vec2& u) const {
    const int x = static_cast<int>(std::floor(u.x() / scale));
    const int y = static_cast<int>(std::floor(u.y() / scale));
    if (x < 0 || y < 0 || x >= distance.cols || y >= distance.rows) return 0;
    return distance.at<float>(y, x) * scale;
  }
};

Coverage coverageOf(const SurfaceMesh& mesh, cv::Size size, int scale) {
  const int cols = (size.width + scale - 1) / scale, rows = (size.height + scale - 1) / scale;
  cv::Mat covered(rows + 2, cols + 2, CV_8UC1, cv::Scalar(0));
  constexpr int kShift = 4;  // sub-cell vertex positions for the rasteriser
  for (const Eigen::Vector3i& f : mesh.faces) {
    cv::Point corners[3];
    for (int k = 0; k < 3; ++k) {
      const Vec2& u = mesh.projector[static_cast<std::size_t>(f[k])];
      corners[k] = cv::Point(static_cast<int>(std::lround((u.x() / scale + 1) * (1 << kShift))),
                             static_cast<int>(std::lround((u.y() / scale + 1) * (1 << kShift))));
    }
    cv::fillConvexPoly(covered, corners, 3, cv::Scalar(255), cv::LINE_8, kShift);
  }
  covered.row(0).setTo(0);
  covered.row(covered.rows - 1).setTo(0);
  covered.col(0).setTo(0);
  covered.col(covered.cols - 1).setTo(0);
  cv::Mat distance;
  cv::distanceTransform(covered, distance, cv::DIST_L2, cv::DIST_MASK_5);
  Coverage out;
  out.distance = distance(cv::Rect(1, 1, cols, rows)).clone();
  out.scale = scale;
  return out;
}

Result<geom::MeshIntersector> intersectorOf(const SurfaceMesh& mesh) {
  geom::TriangleMesh t;
  t.vertices = mesh.vertices;
  t.faces = mesh.faces;
  return geom::MeshIntersector::build(std::move(t));
}

std::optional<Vec2> project(const Mat34& P, const Vec3& X) {
  const Vec3 x = P * X.homogeneous();
  if (!(x.z() > 1e-12)) return std::nullopt;
  return Vec2(x.x() / x.z(), x.y() / x.z());
}

struct Along {
  Vec3 point;
  double weight;
};

// The points every other mesh gives along the ray from projector m's centre through X,
// each with its eq. 4.4 weight (nothing where that mesh does not cover the point).
std::vector<Along> othersAlong(std::size_t m, const Vec3& centre, const Vec3& X,
                               const std::vector<UnifyProjector>& projectors,
                               const std::vector<geom::MeshIntersector>& surfaces,
                               const std::vector<Coverage>& coverage, double max_gap) {
  std::vector<Along> out;
  const double t0 = (X - centre).norm();
  if (!(t0 > max_gap)) return out;
  const geom::Ray ray{centre, (X - centre) / t0};
  for (std::size_t n = 0; n < projectors.size(); ++n) {
    if (n == m) continue;
    const auto hit = surfaces[n].intersect(ray, {t0 - max_gap, t0 + max_gap});
    if (!hit) continue;
    const auto u = project(projectors[n].P, hit->point);
    if (!u) continue;
    const double d = coverage[n].at(*u);
    if (d > 0) out.push_back({hit->point, d});
  }
  return out;
}

}  // namespace

Result<UnifyReport> unifyMeshes(std::vector<UnifyProjector>& projectors,
                                const UnifyOptions& options) {
  if (!(options.max_gap_m > 0) || !std::isfinite(options.max_gap_m) || options.coverage_scale < 1 ||
      options.coverage_scale > 64) {
    return fail(ErrorCode::kInvalidInput, "mesh unification: options out of range");
  }
  std::vector<Vec3> centres;
  std::vector<geom::MeshIntersector> surfaces;
  std::vector<Coverage> coverage;
  for (const UnifyProjector& p : projectors) {
    if (p.size.width < 2 || p.size.height < 2 || p.size.width > 16384 || p.size.height > 16384)
      return fail(ErrorCode::kInvalidInput, "mesh unification: framebuffer size out of range");
    if (!p.P.allFinite()) return fail(ErrorCode::kInvalidInput, "mesh unification: non-finite P");
    const Eigen::FullPivLU<Mat3> lu(p.P.leftCols<3>());
    if (!lu.isInvertible()) return fail(ErrorCode::kInvalidInput, "mesh unification: singular P");
    if (p.mesh.projector.size() != p.mesh.vertices.size())
      return fail(ErrorCode::kInvalidInput, "mesh unification: a pixel for every vertex needed");
    for (const Vec2& u : p.mesh.projector) {
      // Pixels are rasterised: they must lie near the frame (a frame's size off at most).
      if (!u.allFinite() || u.x() < -p.size.width || u.y() < -p.size.height ||
          u.x() > 2.0 * p.size.width || u.y() > 2.0 * p.size.height)
        return fail(ErrorCode::kInvalidInput,
                    "mesh unification: a vertex's pixel is off its frame");
    }
    auto surface = intersectorOf(p.mesh);
    if (!surface) return tl::unexpected(surface.error());
    centres.push_back(-lu.solve(p.P.col(3)));
    surfaces.push_back(std::move(*surface));
    coverage.push_back(coverageOf(p.mesh, p.size, options.coverage_scale));
  }
  UnifyReport report;
  double sq = 0;
  int pairs = 0;
  std::vector<std::vector<Vec3>> unified(projectors.size());
  std::vector<std::vector<char>> shared(projectors.size());
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    const SurfaceMesh& mesh = projectors[m].mesh;
    unified[m] = mesh.vertices;
    shared[m].assign(mesh.vertices.size(), 0);
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
      const Vec3& X = mesh.vertices[k];
      const auto others =
          othersAlong(m, centres[m], X, projectors, surfaces, coverage, options.max_gap_m);
      ++report.vertices;
      if (others.empty()) continue;
      shared[m][k] = 1;
      ++report.shared;
      const double own = coverage[m].at(mesh.projector[k]);
      Vec3 sum = own * X;
      double weight = own;
      for (const Along& o : others) {
        const double gap = (o.point - X).norm();
        sq += gap * gap;
        ++pairs;
        report.gap_max_m = std::max(report.gap_max_m, gap);
        sum += o.weight * o.point;
        weight += o.weight;
      }
      if (weight > 0) unified[m][k] = sum / weight;
    }
  }
  report.gap_rms_m = pairs ? std::sqrt(sq / pairs) : 0;
  // The unified meshes, and how far apart they still are along the same rays.
  std::vector<geom::MeshIntersector> after;
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    projectors[m].mesh.vertices = std::move(unified[m]);
    auto surface = intersectorOf(projectors[m].mesh);
    if (!surface) return tl::unexpected(surface.error());
    after.push_back(std::move(*surface));
  }
  sq = 0;
  pairs = 0;
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    const SurfaceMesh& mesh = projectors[m].mesh;
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
      if (!shared[m][k]) continue;
      const Vec3& X = mesh.vertices[k];
      for (const Along& o :
           othersAlong(m, centres[m], X, projectors, after, coverage, options.max_gap_m)) {
        const double gap = (o.point - X).norm();
        sq += gap * gap;
        report.gap_after_max_m = std::max(report.gap_after_max_m, gap);
        ++pairs;
      }
    }
  }
  report.gap_after_rms_m = pairs ? std::sqrt(sq / pairs) : 0;
  return report;
}

}  // namespace procam::surface
