#include "calibration/projector_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "geometry/projection_matrix.hpp"

namespace procam::calib {
namespace {

// Robust start for route (a): MSAC (truncated quadratic cost) over minimal 6-point
// DLT fits, the sample count adapted to the best inlier fraction so far (99.9%
// confidence of one clean sample). Triangulated points from wrongly decoded pixels
// are gross outliers that bias a least-squares start beyond what the iterative
// rejection can recover from at high camera noise. Returns the inlier mask
// (residual below `threshold` px) of the best model, or all ones when no sample gave
// a model (e.g. coplanar points: the full fit then reports the degeneracy).
std::vector<std::uint8_t> msacInliers(std::span<const Vec3> world, std::span<const Vec2> pixels,
                                      double threshold) {
  const std::size_t n = world.size();
  std::vector<std::uint8_t> best_mask(n, 1);
  if (n < 12) return best_mask;
  std::mt19937 rng(12345);  // deterministic: the same data gives the same result
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  const double t2 = threshold * threshold;
  double best_cost = std::numeric_limits<double>::infinity();
  std::size_t needed = 200;
  const std::size_t max_samples = 1000;
  geom::ProjectionOptions minimal;
  minimal.refine = false;
  Points3 sw(6);
  Points2 sp(6);
  std::vector<std::uint8_t> mask(n);
  for (std::size_t it = 0; it < std::min(needed, max_samples); ++it) {
    for (int k = 0; k < 6; ++k) {
      const std::size_t i = pick(rng);
      sw[k] = world[i];
      sp[k] = pixels[i];
    }
    auto fit = geom::fitProjectionMatrix(sw, sp, minimal);
    if (!fit) continue;
    double cost = 0;
    std::size_t inliers = 0;
    for (std::size_t i = 0; i < n && cost < best_cost; ++i) {
      const auto p = geom::projectWith(fit->P, world[i]);
      const double e2 = p ? (*p - pixels[i]).squaredNorm() : t2;
      mask[i] = e2 < t2;
      inliers += mask[i];
      cost += std::min(e2, t2);
    }
    if (cost >= best_cost) continue;
    best_cost = cost;
    best_mask = mask;
    const double w = static_cast<double>(inliers) / static_cast<double>(n);
    const double clean = std::pow(w, 6);
    needed = clean >= 1 - 1e-12
                 ? 1
                 : static_cast<std::size_t>(std::ceil(std::log(1e-3) / std::log1p(-clean)));
    needed = std::max<std::size_t>(needed, 8);
  }
  return best_mask;
}

// `refine`: Levenberg-Marquardt after the DLT (the final fit); without it, the
// normalised DLT alone (enough to tell inliers while the set is being settled).
Result<ProjectorCalibration> fromCorrespondences(std::span<const Vec3> world,
                                                 std::span<const Vec2> projector,
                                                 bool refine = true) {
  geom::ProjectionOptions options;
  options.refine = refine;
  auto fit = geom::fitProjectionMatrix(world, projector, options);
  if (!fit) return tl::unexpected(fit.error());
  auto krt = geom::decomposeProjectionMatrix(fit->P);
  if (!krt) return tl::unexpected(krt.error());
  ProjectorCalibration c;
  c.K = krt->K;
  c.pose = krt->pose;
  c.rms_px = fit->rms;
  c.points = static_cast<int>(world.size());
  return c;
}

}  // namespace

Result<ProjectorCalibration> calibrateProjectorFromSurface(const surface::SurfacePoints& points) {
  std::vector<std::uint8_t> keep = msacInliers(points.world, points.projector, 3.0);
  Points3 start_world;
  Points2 start_projector;
  for (std::size_t i = 0; i < points.world.size(); ++i)
    if (keep[i])
      start_world.push_back(points.world[i]), start_projector.push_back(points.projector[i]);
  auto c = fromCorrespondences(start_world, start_projector, false);
  // Rejection at 3 sigma of the residual norm (sigma from its median: for 2D
  // Gaussian noise the median norm is 1.177 sigma, floor 0.1 px), refitting until
  // the inlier set is stable; gross outliers (a wrongly unwrapped phase) bias the
  // first fits, so this takes a few rounds. DLT fits while the set settles, one
  // Levenberg-Marquardt fit on the final set.
  Points3 world = std::move(start_world);
  Points2 projector = std::move(start_projector);
  for (int round = 0; round < 6 && c; ++round) {
    const Mat34 P = geom::projectionMatrix(c->K, c->pose);
    std::vector<double> err(points.world.size(), 1e9);
    std::vector<double> kept;
    for (std::size_t i = 0; i < points.world.size(); ++i) {
      if (auto p = geom::projectWith(P, points.world[i]))
        err[i] = (*p - points.projector[i]).norm();
      if (keep[i]) kept.push_back(err[i]);
    }
    if (kept.empty()) break;
    std::nth_element(kept.begin(), kept.begin() + kept.size() / 2, kept.end());
    const double limit = std::max(0.1, 3.0 * kept[kept.size() / 2] / 1.177);
    world.clear();
    projector.clear();
    bool changed = false;
    for (std::size_t i = 0; i < points.world.size(); ++i) {
      const std::uint8_t k = err[i] <= limit;
      changed |= k != keep[i];
      keep[i] = k;
      if (k) world.push_back(points.world[i]), projector.push_back(points.projector[i]);
    }
    if (!changed) break;
    c = fromCorrespondences(world, projector, false);
  }
  if (c) c = fromCorrespondences(world, projector);
  if (c) c->inliers = std::move(keep);
  if (!c && c.error().code == ErrorCode::kCoplanar)
    return fail(ErrorCode::kCoplanar,
                "the decoded surface is planar, so the projector's depth scale is ambiguous "
                "([Raskar02] §4.1.1): add a non-planar object to the scene for this calibration, "
                "or calibrate from the plane at two or more orientations (route b)");
  return c;
}

Result<ProjectorCalibration> calibrateProjectorFromFiducials(std::span<const Vec3> world,
                                                             std::span<const Vec2> projector) {
  if (world.size() != projector.size())
    return fail(ErrorCode::kInvalidInput,
                "fiducials: as many projector pixels as 3D points needed");
  if (world.size() < 6)
    return fail(ErrorCode::kTooFewPoints, "fiducials: at least 6 points are needed (11 unknowns)");
  auto c = fromCorrespondences(world, projector);
  if (!c && c.error().code == ErrorCode::kCoplanar)
    return fail(ErrorCode::kCoplanar, "fiducials are coplanar: place them on a non-planar object");
  return c;
}

}  // namespace procam::calib
