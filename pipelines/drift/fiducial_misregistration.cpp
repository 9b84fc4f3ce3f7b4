#include "fiducial_misregistration.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <vector>

#include "geometry/intersect.hpp"

namespace procam::drift {

Result<Misregistration> fiducialMisregistration(std::span<const Vec2> shown,
                                                std::span<const FiducialCorner> found,
                                                const geom::PlaneHomography& projector_to_plane,
                                                const geom::CameraModel& camera,
                                                const MisregistrationOptions& options) {
  const Mat3& H = projector_to_plane.H;
  Eigen::FullPivLU<Mat3> lu(H);
  if (!H.allFinite() || !lu.isInvertible()) {
    return fail(ErrorCode::kInvalidInput,
                "fiducial check: the projector's collineation is singular");
  }
  const Mat3 Hinv = lu.inverse();
  const geom::PlaneBasis& basis = projector_to_plane.basis;
  const Vec3 n = basis.normal().normalized();
  const geom::Plane plane{n, -n.dot(basis.origin)};
  Misregistration m;
  for (const Vec2& p : shown) {
    if (!p.allFinite())
      return fail(ErrorCode::kInvalidInput, "fiducial check: a corner is not finite");
    const Vec3 ab = H * Vec3(p.x(), p.y(), 1.0);
    if (!(std::abs(ab.z()) > 1e-12)) continue;
    auto px = camera.project(basis.toWorld(ab.head<2>() / ab.z()));
    if (px && camera.inImage(*px)) ++m.tiles_seen;
  }
  m.tiles_textured = m.tiles_seen;
  std::vector<TileShift> tiles;
  for (const FiducialCorner& c : found) {
    if (!c.drawn.allFinite() || !c.camera.allFinite()) {
      return fail(ErrorCode::kInvalidInput, "fiducial check: a corner is not finite");
    }
    // Where the rig model puts the framebuffer point the camera found the corner at.
    auto ray = camera.backproject(c.camera);
    auto hit = ray ? geom::intersectPlane(*ray, plane) : std::nullopt;
    if (!hit) continue;
    const Vec3 q = Hinv * basis.toPlane(hit->point).homogeneous();
    if (!(std::abs(q.z()) > 1e-12)) continue;
    TileShift t;
    t.drawn = c.drawn;
    t.seen_at = q.head<2>() / q.z();
    t.response = 1.0;  // a decoded marker: no correlation peak to weigh it by
    tiles.push_back(t);
  }
  // A projector that moved may bring corners into view the rig model puts outside it.
  m.tiles_seen = std::max(m.tiles_seen, static_cast<int>(tiles.size()));
  m.tiles_textured = m.tiles_seen;
  fitShiftField(std::move(tiles), options, m);
  return m;
}

Result<Misregistration> fiducialMisregistration(std::span<const Vec2> shown,
                                                std::span<const FiducialCorner> found,
                                                const cv::Mat& map, const WorkGrid& grid,
                                                const MisregistrationOptions& options) {
  if (map.type() != CV_32FC2 || map.size() != grid.size()) {
    return fail(ErrorCode::kInvalidInput,
                "fiducial check: the camera's map is not CV_32FC2 of the work grid's size");
  }
  Misregistration m;
  for (const Vec2& p : shown) {
    if (!p.allFinite())
      return fail(ErrorCode::kInvalidInput, "fiducial check: a corner is not finite");
    if (mappedCameraPixel(map, grid.toWork(p))) ++m.tiles_seen;
  }
  std::vector<TileShift> tiles;
  for (const FiducialCorner& c : found) {
    if (!c.drawn.allFinite() || !c.camera.allFinite()) {
      return fail(ErrorCode::kInvalidInput, "fiducial check: a corner is not finite");
    }
    auto w = workPixelSeenAt(map, c.camera, grid.toWork(c.drawn));
    if (!w) continue;
    TileShift t;
    t.drawn = c.drawn;
    t.seen_at = grid.toFramebuffer(*w);
    t.response = 1.0;
    tiles.push_back(t);
  }
  m.tiles_seen = std::max(m.tiles_seen, static_cast<int>(tiles.size()));
  m.tiles_textured = m.tiles_seen;
  fitShiftField(std::move(tiles), options, m);
  return m;
}

}  // namespace procam::drift
