#include "calibration/stereo_route.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "surface/projector_samples.hpp"
#include "surface/stereo_points.hpp"

namespace procam::calib {

double sampleRadius(const sl::PatternSet& set) {
  if (set.options.mode == sl::Mode::kGrayPhase) return 2.0;
  return std::max({2.0, static_cast<double>(set.columns.cell), static_cast<double>(set.rows.cell)});
}

namespace {

// The projector grid nodes `v` decoded, where its camera sees each.
Result<surface::ProjectorSamples> samplesOf(const sl::PatternSet& set, const DecodedView& v,
                                            int step) {
  if (v.decoded.u.cols != v.camera.width || v.decoded.u.rows != v.camera.height)
    return fail(ErrorCode::kInvalidInput,
                "captures of camera '" + v.name + "' are " + std::to_string(v.decoded.u.cols) +
                    "x" + std::to_string(v.decoded.u.rows) + " but its calibration is " +
                    std::to_string(v.camera.width) + "x" + std::to_string(v.camera.height));
  return surface::sampleProjectorGrid(v.decoded, set.options.width, set.options.height,
                                      {.step = step, .radius = sampleRadius(set)});
}

Result<surface::SurfacePoints> atLeastTwenty(Result<surface::SurfacePoints> points,
                                             const char* seen_by) {
  if (!points) return tl::unexpected(points.error());
  if (points->world.size() < 20)
    return fail(ErrorCode::kTooFewPoints, "only " + std::to_string(points->world.size()) +
                                              " projector nodes were seen by " + seen_by +
                                              " (need 20)");
  return points;
}

}  // namespace

Result<surface::SurfacePoints> triangulateNodes(const sl::PatternSet& set, const DecodedView& a,
                                                const DecodedView& b, int step) {
  auto sa = samplesOf(set, a, step);
  if (!sa) return tl::unexpected(sa.error());
  auto sb = samplesOf(set, b, step);
  if (!sb) return tl::unexpected(sb.error());
  return atLeastTwenty(surface::triangulateStereo(a.camera, *sa, b.camera, *sb), "both cameras");
}

Result<surface::SurfacePoints> triangulateWithProjector(const sl::PatternSet& set,
                                                        const geom::CameraModel& projector,
                                                        const DecodedView& view, int step) {
  if (projector.width != set.options.width || projector.height != set.options.height)
    return fail(ErrorCode::kInvalidInput, "the projector's model is not the pattern set's size");
  auto seen = samplesOf(set, view, step);
  if (!seen) return tl::unexpected(seen.error());
  // The projector "sees" each node at the node itself.
  surface::ProjectorSamples own = *seen;
  own.camera = own.projector;
  return atLeastTwenty(surface::triangulateStereo(projector, own, view.camera, *seen),
                       "the projector and the camera");
}

namespace {

// A surface is taken as one plane when this share of its nodes lies within five
// times their own noise of the best plane (at least 0.5 mm): relief below the noise
// cannot separate a projector's depth from its focal length. Five, not three: Gray
// codes alone decode cell centres, whose error is far from Gaussian (86 % of the
// tiled_wall nodes lie within three of their sigmas of the wall, 2.6 mm).
constexpr double kPlaneShare = 0.9;

// The nodes' noise along `normal`, from second differences along the projector grid's
// rows and columns: a local plane cancels in them and the median ignores the few at a
// kink (a corner's edge); for white noise var(r[i-1] - 2 r[i] + r[i+1]) = 6 sigma^2.
double nodeNoise(const surface::SurfacePoints& p, const Vec3& normal) {
  std::vector<double> d2;
  auto depth = [&](int x, int y) -> std::optional<double> {
    if (x < 0 || y < 0 || x >= p.nodes_x || y >= p.nodes_y) return std::nullopt;
    const std::int32_t i = p.index[std::size_t(y) * std::size_t(p.nodes_x) + std::size_t(x)];
    if (i < 0) return std::nullopt;
    return normal.dot(p.world[std::size_t(i)]);
  };
  for (int y = 0; y < p.nodes_y; ++y) {
    for (int x = 0; x < p.nodes_x; ++x) {
      const auto c = depth(x, y);
      if (!c) continue;
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const auto a = depth(x - dx, y - dy), b = depth(x + dx, y + dy);
        if (a && b) d2.push_back(std::abs(*a - 2 * *c + *b));
      }
    }
  }
  if (d2.empty()) return 0;
  std::nth_element(d2.begin(), d2.begin() + std::ptrdiff_t(d2.size() / 2), d2.end());
  return d2[d2.size() / 2] / (0.6745 * std::sqrt(6.0));
}

struct PlaneShare {
  geom::PlaneFit fit;
  double share = 0;
  double threshold = 0;  // metres
};

double planeThreshold(const surface::SurfacePoints& points, const Vec3& normal) {
  return std::max(0.0005, 5 * nodeNoise(points, normal));
}

Result<PlaneShare> bestPlane(const surface::SurfacePoints& points) {
  auto rough = geom::fitPlane(points.world);
  if (!rough) return tl::unexpected(rough.error());
  const double threshold = planeThreshold(points, rough->plane.n);
  auto fit = geom::fitPlaneRansac(points.world, {.threshold = threshold});
  if (!fit) return tl::unexpected(fit.error());
  const double share = double(fit->inliers.size()) / double(points.world.size());
  return PlaneShare{std::move(*fit), share, threshold};
}

// `plane` with the nodes within `threshold` of it as inliers and their RMS distance.
PlaneShare onPlane(const surface::SurfacePoints& points, const geom::Plane& plane,
                   double threshold) {
  PlaneShare out;
  out.fit = geom::planeInliers(points.world, plane, threshold);
  out.threshold = threshold;
  out.share =
      points.world.empty() ? 0 : double(out.fit.inliers.size()) / double(points.world.size());
  return out;
}

std::string millimetres(double metres) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f mm", metres * 1000);
  return buf;
}

}  // namespace

Result<geom::PlaneFit> triangulatedPlane(const surface::SurfacePoints& nodes,
                                         const std::optional<geom::Plane>& prior) {
  if (prior && prior->n.allFinite() && std::isfinite(prior->d) && prior->n.norm() > 0.5) {
    PlaneShare on = onPlane(nodes, *prior, planeThreshold(nodes, prior->n));
    if (on.share >= kPlaneShare) return std::move(on.fit);
  }
  auto best = bestPlane(nodes);
  if (!best) return tl::unexpected(best.error());
  if (best->share < kPlaneShare)
    return fail(ErrorCode::kDegenerate,
                "the triangulated surface is not one plane: " +
                    std::to_string(int(100 * best->share)) + " % of the nodes lie within " +
                    millimetres(best->threshold) + " (five times their noise) of it");
  return std::move(best->fit);
}

Result<StereoRouteResult> solveStereoRoute(const sl::PatternSet& set, const DecodedView& a,
                                           const DecodedView& b, int step) {
  auto points = triangulateNodes(set, a, b, step);
  if (!points) return tl::unexpected(points.error());
  return solveStereoRoute(*points);
}

Result<StereoRouteResult> solveStereoRoute(const surface::SurfacePoints& nodes) {
  StereoRouteResult out;
  out.triangulated = nodes.world.size();
  // A plane within the noise leaves the projection matrix undetermined
  // ([Raskar02] §4.1.1), however thick the noise makes it look to the DLT's own check.
  if (auto best = bestPlane(nodes); best && best->share >= kPlaneShare) {
    return fail(ErrorCode::kCoplanar,
                std::to_string(int(100 * best->share)) + " % of the " +
                    std::to_string(nodes.world.size()) + " triangulated nodes lie within " +
                    millimetres(best->threshold) +
                    " (five times their noise) of one plane: a planar scene gives "
                    "no projection matrix; add relief (a second wall at an angle) or take the "
                    "plane route");
  }
  auto projector = calibrateProjectorFromSurface(nodes);
  if (!projector) return tl::unexpected(projector.error());
  // The surface from the points consistent with the calibrated projector.
  const surface::SurfacePoints kept = surface::keepPoints(nodes, projector->inliers);
  out.consistent = kept.world.size();
  auto model = surface::buildSurface(kept);
  if (!model) return tl::unexpected(model.error());
  out.projector = std::move(*projector);
  out.surface = std::move(*model);
  return out;
}

}  // namespace procam::calib
