#include "wall_from_views.hpp"

#include <cmath>
#include <vector>

#include "core/units.hpp"
#include "geometry/triangulate.hpp"

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

}  // namespace

bool wallMoved(const WallSeen& seen, double min_offset_m, double min_tilt_deg) {
  const double off = std::abs(seen.offset_m);
  return (off > min_offset_m && off > 6 * seen.offset_se_m) ||
         (seen.tilt_deg > min_tilt_deg && seen.tilt_deg > 6 * seen.tilt_se_deg);
}

Result<WallSeen> wallFromTwoViews(const WallView& a, const WallView& b,
                                  const geom::Plane& rig_plane) {
  if (!usable(a) || !usable(b)) {
    return fail(ErrorCode::kInvalidInput, "wall from two views: a view without its check or map");
  }
  std::vector<Vec3> points;
  for (const TileShift& ta : a.drift->tiles) {
    if (!ta.inlier) continue;
    for (const TileShift& tb : b.drift->tiles) {
      if (!tb.inlier || (tb.drawn - ta.drawn).norm() > 1e-6) continue;
      const auto pa = foundAt(a, ta), pb = foundAt(b, tb);
      if (!pa || !pb) break;
      auto ra = a.camera->backproject(*pa);
      auto rb = b.camera->backproject(*pb);
      if (!ra || !rb) break;
      // Rays that pass apart saw different points (the content moved between the checks).
      auto x = geom::triangulateRays(*ra, *rb);
      if (x && x->t1 > 0 && x->t2 > 0 && x->point.allFinite() && x->gap <= kMaxRayGapM) {
        points.push_back(x->point);
      }
      break;
    }
  }
  if (points.size() < 8) {
    return fail(ErrorCode::kTooFewPoints,
                "wall from two views: " + std::to_string(points.size()) +
                    " content points registered by both cameras (8 needed)");
  }
  auto fit = geom::fitPlane(points);
  if (!fit) return tl::unexpected(fit.error());
  WallSeen out;
  out.plane = fit->plane;
  out.rms_m = fit->rms;
  out.points = static_cast<int>(points.size());
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

}  // namespace procam::drift
