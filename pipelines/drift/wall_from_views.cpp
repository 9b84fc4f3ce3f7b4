#include "wall_from_views.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "core/units.hpp"
#include "geometry/intersect.hpp"
#include "geometry/triangulate.hpp"
#include "projector_correction.hpp"

namespace procam::drift {
namespace {

bool usable(const WallView& v) {
  return v.camera && v.drift && v.map && v.map->type() == CV_32FC2 &&
         v.map->size() == v.grid.size();
}

// The camera pixel where the view found the content drawn at `tile.drawn`.
std::optional<Vec2> foundAt(const WallView& v, const TileShift& tile) {
  return mappedCameraPixel(*v.map, v.grid.toWork(tile.seen_at));
}

// The wall fitted to the triangulated content points, against the rig's plane.
Result<WallSeen> wallFromPoints(const std::vector<Vec3>& points, int rays,
                                const geom::Plane& rig_plane, const char* what) {
  if (points.size() < 8) {
    return fail(ErrorCode::kTooFewPoints, std::string(what) + ": " + std::to_string(points.size()) +
                                              " content points whose rays met (8 needed)");
  }
  auto fit = geom::fitPlane(points);
  if (!fit) return tl::unexpected(fit.error());
  WallSeen out;
  out.plane = fit->plane;
  out.rms_m = fit->rms;
  out.points = static_cast<int>(points.size());
  out.rays = rays;
  double sum = 0, sq = 0;
  for (const Vec3& x : points) {
    const double d = rig_plane.signedDistance(x);
    sum += d;
    sq += d * d;
  }
  const double n = static_cast<double>(points.size());
  out.offset_m = sum / n;
  const double var = std::max(0.0, sq / n - out.offset_m * out.offset_m);
  out.offset_se_m = std::sqrt(var / (n - 1));
  out.shifted = {rig_plane.n, rig_plane.d - out.offset_m};
  const double c = std::min(1.0, std::abs(out.plane.n.dot(rig_plane.n)));
  out.tilt_deg = radToDeg(std::acos(c));
  // The fitted normal's standard error: the points' scatter over their spread about
  // their centroid, in n points.
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& x : points) centroid += x;
  centroid /= n;
  double spread = 0;
  for (const Vec3& x : points) spread += (x - centroid).squaredNorm();
  spread = std::sqrt(spread / n);
  out.tilt_se_deg = spread > 0 ? radToDeg(out.rms_m / (spread * std::sqrt(n))) : 90.0;
  return out;
}

// The rays' meeting point when they meet in front of both views within kMaxRayGapM.
std::optional<Vec3> meeting(const Result<geom::RayRayPoint>& x) {
  if (x && x->t1 > 0 && x->t2 > 0 && x->point.allFinite() && x->gap <= kMaxRayGapM) {
    return x->point;
  }
  return std::nullopt;
}

}  // namespace

bool wallMoved(const WallSeen& seen, double min_offset_m, double min_tilt_deg) {
  const double off = std::abs(seen.offset_m);
  return (off > min_offset_m && off > 6 * seen.offset_se_m) ||
         (seen.tilt_deg > min_tilt_deg && seen.tilt_deg > 6 * seen.tilt_se_deg);
}

bool wallTurned(const WallSeen& seen) {
  return seen.tilt_deg > 6 * seen.tilt_se_deg && seen.tilt_deg > seen.tilt_floor_deg;
}

geom::Plane wallToKeep(const WallSeen& seen) {
  return wallTurned(seen) ? seen.plane : seen.shifted;
}

Result<WallSeen> wallFromTwoViews(const WallView& a, const WallView& b,
                                  const geom::Plane& rig_plane) {
  if (!usable(a) || !usable(b)) {
    return fail(ErrorCode::kInvalidInput, "wall from two views: a view without its check or map");
  }
  std::vector<Vec3> points;
  int rays = 0;
  for (const TileShift& ta : a.drift->tiles) {
    if (!ta.inlier) continue;
    for (const TileShift& tb : b.drift->tiles) {
      if (!tb.inlier || (tb.drawn - ta.drawn).norm() > 1e-6) continue;
      const auto pa = foundAt(a, ta), pb = foundAt(b, tb);
      if (!pa || !pb) break;
      auto ra = a.camera->backproject(*pa);
      auto rb = b.camera->backproject(*pb);
      if (!ra || !rb) break;
      ++rays;
      // Rays that pass apart saw different points (the content moved between the checks).
      if (auto x = meeting(geom::triangulateRays(*ra, *rb))) points.push_back(*x);
      break;
    }
  }
  return wallFromPoints(points, rays, rig_plane, "wall from two views");
}

Result<WallSeen> wallFromProjectorAndView(const geom::CameraModel& projector,
                                          const WallView& camera, const geom::Plane& rig_plane) {
  if (!usable(camera)) {
    return fail(ErrorCode::kInvalidInput,
                "wall from the projector and a camera: a view without its check or map");
  }
  std::vector<Vec3> points;
  int rays = 0;
  double gap_sq = 0, shift_sq = 0;
  for (const TileShift& t : camera.drift->tiles) {
    if (!t.inlier) continue;
    const auto found = foundAt(camera, t);
    const auto predicted = mappedCameraPixel(*camera.map, camera.grid.toWork(t.drawn));
    if (!found || !predicted) continue;
    auto rp = projector.backproject(t.drawn);
    auto rf = camera.camera->backproject(*found);
    auto rr = camera.camera->backproject(*predicted);
    if (!rp || !rf || !rr) continue;
    auto x = geom::triangulateRays(*rp, *rf);
    auto on = geom::intersectPlane(*rf, rig_plane);
    auto was = geom::intersectPlane(*rr, rig_plane);
    if (!x || !x->point.allFinite() || !on || !was) continue;
    ++rays;
    gap_sq += x->gap * x->gap;
    shift_sq += (on->point - was->point).squaredNorm();
    if (auto m = meeting(x)) points.push_back(*m);
  }
  if (rays == 0) {
    return fail(ErrorCode::kTooFewPoints,
                "wall from the projector and a camera: no content point registered");
  }
  const double gap_rms = std::sqrt(gap_sq / rays), shift_rms = std::sqrt(shift_sq / rays);
  if (static_cast<double>(points.size()) < kMinMetShare * rays ||
      !(gap_rms <= kMaxGapShare * shift_rms)) {
    return fail(ErrorCode::kTooFewPoints,
                "wall from the projector and a camera: the rays of " +
                    std::to_string(points.size()) + " of " + std::to_string(rays) +
                    " content points met, passing " + std::to_string(1e3 * gap_rms) +
                    " mm RMS apart against a shift of " + std::to_string(1e3 * shift_rms) +
                    " mm RMS on the wall (the projector or the camera moved, or too little "
                    "moved to tell)");
  }
  auto out = wallFromPoints(points, rays, rig_plane, "wall from the projector and a camera");
  if (out) {
    out->gap_rms_m = gap_rms;
    out->shift_rms_m = shift_rms;
  }
  return out;
}

Result<WallSeen> wallFromOneCamera(const rig::RigProjector& projector,
                                   const geom::PlaneHomography& tile, const WallView& camera,
                                   const geom::Plane& rig_plane) {
  if (!projector.pose_known || !projector.intrinsics_known || !camera.drift) {
    return fail(ErrorCode::kInvalidInput,
                "wall from one camera: the projector's pose and intrinsics are needed");
  }
  auto moved = correctProjector(projector, tile, *camera.drift);
  if (!moved) {
    return fail(
        ErrorCode::kDegenerate,
        "wall from one camera: no projector pose to compare with: " + moved.error().message);
  }
  const Eigen::AngleAxisd turn(moved->projector.pose.R * projector.pose.R.transpose());
  const double turn_deg = radToDeg(std::abs(turn.angle()));
  if (!(turn_deg <= kMaxWallProjectorTurnDeg)) {
    return fail(ErrorCode::kDegenerate,
                "wall from one camera: the content fits the projector "
                "turned " +
                    std::to_string(turn_deg) + " deg");
  }
  auto seen = wallFromProjectorAndView(projector.model(), camera, rig_plane);
  if (seen) {
    seen->projector_turn_deg = turn_deg;
    seen->tilt_floor_deg = kOneCameraTiltFloorDeg;
  }
  return seen;
}

}  // namespace procam::drift
