#include "calibration/projector_calibration.hpp"

#include <algorithm>

#include "geometry/projection_matrix.hpp"

namespace procam::calib {
namespace {

Result<ProjectorCalibration> fromCorrespondences(std::span<const Vec3> world,
                                                 std::span<const Vec2> projector) {
  auto fit = geom::fitProjectionMatrix(world, projector);
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
  auto c = fromCorrespondences(points.world, points.projector);
  // Rejection at 3 sigma of the residual norm (sigma from its median: for 2D
  // Gaussian noise the median norm is 1.177 sigma, floor 0.1 px), refitting until
  // the inlier set is stable; gross outliers (a wrongly unwrapped phase) bias the
  // first fits, so this takes a few rounds.
  std::vector<std::uint8_t> keep(points.world.size(), 1);
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
    Points3 world;
    Points2 projector;
    bool changed = false;
    for (std::size_t i = 0; i < points.world.size(); ++i) {
      const std::uint8_t k = err[i] <= limit;
      changed |= k != keep[i];
      keep[i] = k;
      if (k) world.push_back(points.world[i]), projector.push_back(points.projector[i]);
    }
    if (!changed) break;
    c = fromCorrespondences(world, projector);
  }
  if (c) c->inliers = std::move(keep);
  if (!c && c.error().code == ErrorCode::kCoplanar)
    return fail(ErrorCode::kCoplanar,
                "the decoded surface is planar, so the projector's depth scale is ambiguous "
                "(seed 4.1.1): add a non-planar object to the scene for this calibration, "
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
