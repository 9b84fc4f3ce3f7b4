#include "calibration/two_view_plane.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "geometry/triangulate.hpp"

namespace procam::calib {
namespace {

constexpr double kOnPlaneShare = 0.9;
constexpr std::size_t kMinPoints = 8;
// sin(2 degrees): rays closer to parallel leave a point's depth 30 times its lateral noise.
constexpr double kMinSine = 0.0349;

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

Result<TwoViewPlane> planeFromTwoViews(const geom::CameraModel& camera_a,
                                       const geom::CameraModel& camera_b,
                                       std::span<const TwoViewPoint> points, const std::string& a,
                                       const std::string& b,
                                       const std::optional<geom::Plane>& prior, double max_gap) {
  Points3 world;
  std::vector<double> gaps, sines;
  for (const TwoViewPoint& p : points) {
    if (!p.a.allFinite() || !p.b.allFinite()) continue;
    auto ra = camera_a.backproject(p.a);
    auto rb = camera_b.backproject(p.b);
    if (!ra || !rb) continue;
    auto x = geom::triangulateRays(*ra, *rb);
    if (!x || x->t1 <= 0 || x->t2 <= 0 || !(x->gap <= max_gap) || !x->point.allFinite()) continue;
    world.push_back(x->point);
    gaps.push_back(x->gap);
    sines.push_back(ra->dir.cross(rb->dir).norm());
  }
  // A feature matched wrongly passes its partner's ray far off: beyond five times the
  // pairs' own miss distance (the noise, whatever the wall's distance) it is dropped.
  if (!gaps.empty()) {
    const double cut = std::max(1e-4, 5 * 1.4826 * median(gaps));
    std::size_t kept = 0;
    for (std::size_t i = 0; i < world.size(); ++i) {
      if (gaps[i] > cut) continue;
      world[kept] = world[i];
      gaps[kept] = gaps[i];
      sines[kept] = sines[i];
      ++kept;
    }
    world.resize(kept);
    gaps.resize(kept);
    sines.resize(kept);
  }
  const std::string pair = "cameras '" + a + "' and '" + b + "'";
  if (world.size() < kMinPoints) {
    return fail(ErrorCode::kTooFewPoints, pair + " both saw " + std::to_string(world.size()) +
                                              " of " + std::to_string(points.size()) +
                                              " points with rays that meet (need " +
                                              std::to_string(kMinPoints) + ")");
  }
  // The points' noise from the rays themselves, not from their spread about a plane
  // (which a second wall would inflate): the rays' miss distance is the pixel noise
  // across the epipolar plane, in metres at the point; the same noise along it moves
  // the point in depth by 1/sin of the angle between the rays. Medians, so that a few
  // mismatched features do not widen the threshold.
  const double gap_sigma = 1.4826 * median(gaps);
  const double sine = median(sines);
  if (!(sine >= kMinSine)) {
    return fail(ErrorCode::kIllConditioned,
                pair +
                    ": their rays meet at under 2 degrees (median): too short a baseline "
                    "for the distance to triangulate a plane");
  }
  const double noise = gap_sigma / sine;
  const double threshold = std::max(0.0005, 5 * noise);
  TwoViewPlane out;
  out.triangulated = world.size();
  out.noise_m = noise;
  if (prior && prior->n.allFinite() && std::isfinite(prior->d) && prior->n.norm() > 0.5) {
    geom::PlaneFit on = geom::planeInliers(world, *prior, threshold);
    if (double(on.inliers.size()) >= kOnPlaneShare * double(world.size())) {
      out.fit = std::move(on);
      return out;
    }
  }
  auto fit = geom::fitPlaneRansac(world, {.threshold = threshold});
  if (!fit) return tl::unexpected(fit.error());
  const double share = double(fit->inliers.size()) / double(world.size());
  if (share < kOnPlaneShare) {
    char buf[160];
    std::snprintf(
        buf, sizeof buf,
        ": %d %% of the %zu points lie within %.1f mm (five times their depth noise) of one "
        "plane; the surface is not a plane",
        static_cast<int>(100 * share), world.size(), threshold * 1000);
    return fail(ErrorCode::kDegenerate, pair + buf);
  }
  out.fit = std::move(*fit);
  return out;
}

}  // namespace procam::calib
