#include "calibration/stereo_route.hpp"

#include <algorithm>

#include "surface/projector_samples.hpp"
#include "surface/stereo_points.hpp"

namespace procam::calib {

double sampleRadius(const sl::PatternSet& set) {
  if (set.options.mode == sl::Mode::kGrayPhase) return 2.0;
  return std::max({2.0, static_cast<double>(set.columns.cell), static_cast<double>(set.rows.cell)});
}

Result<StereoRouteResult> solveStereoRoute(const sl::PatternSet& set, const DecodedView& a,
                                           const DecodedView& b, int step) {
  const int pw = set.options.width, ph = set.options.height;
  surface::ProjectorSamples samples[2];
  const DecodedView* views[2] = {&a, &b};
  for (int i = 0; i < 2; ++i) {
    const DecodedView& v = *views[i];
    if (v.decoded.u.cols != v.camera.width || v.decoded.u.rows != v.camera.height)
      return fail(ErrorCode::kInvalidInput,
                  "captures of camera '" + v.name + "' are " + std::to_string(v.decoded.u.cols) +
                      "x" + std::to_string(v.decoded.u.rows) + " but its calibration is " +
                      std::to_string(v.camera.width) + "x" + std::to_string(v.camera.height));
    auto s = surface::sampleProjectorGrid(v.decoded, pw, ph,
                                          {.step = step, .radius = sampleRadius(set)});
    if (!s) return tl::unexpected(s.error());
    samples[i] = std::move(*s);
  }
  auto points = surface::triangulateStereo(a.camera, samples[0], b.camera, samples[1]);
  if (!points) return tl::unexpected(points.error());
  StereoRouteResult out;
  out.triangulated = points->world.size();
  if (out.triangulated < 20)
    return fail(ErrorCode::kTooFewPoints,
                "only " + std::to_string(out.triangulated) +
                    " projector nodes were seen by both cameras (need 20)");
  auto projector = calibrateProjectorFromSurface(*points);
  if (!projector) return tl::unexpected(projector.error());
  // The surface from the points consistent with the calibrated projector.
  const surface::SurfacePoints kept = surface::keepPoints(*points, projector->inliers);
  out.consistent = kept.world.size();
  auto model = surface::buildSurface(kept);
  if (!model) return tl::unexpected(model.error());
  out.projector = std::move(*projector);
  out.surface = std::move(*model);
  return out;
}

}  // namespace procam::calib
