#include "calibration/projector_calibration.hpp"

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
    return fail(ErrorCode::kInvalidInput, "fiducials: as many projector pixels as 3D points needed");
  if (world.size() < 6)
    return fail(ErrorCode::kTooFewPoints, "fiducials: at least 6 points are needed (11 unknowns)");
  auto c = fromCorrespondences(world, projector);
  if (!c && c.error().code == ErrorCode::kCoplanar)
    return fail(ErrorCode::kCoplanar, "fiducials are coplanar: place them on a non-planar object");
  return c;
}

}  // namespace procam::calib
