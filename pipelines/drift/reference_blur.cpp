#include "reference_blur.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace procam::drift {

Result<ReferenceBlur> fitReferenceBlur(const cv::Mat& shown, const cv::Mat& camera,
                                       const cv::Mat& map, const WorkGrid& grid,
                                       const MisregistrationOptions& options, const cv::Mat& usable,
                                       std::span<const double> candidates) {
  if (candidates.empty() || !std::is_sorted(candidates.begin(), candidates.end())) {
    return fail(ErrorCode::kInvalidInput,
                "drift check: no reference blur to try, or not ascending");
  }
  ReferenceBlur out;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    MisregistrationOptions o = options;
    o.reference_blur_px = candidates[i];
    auto m = measureMisregistration(shown, camera, map, grid, o, usable);
    if (!m) return tl::unexpected(m.error());
    if (i == 0) {
      out.at_best = *m;
      // Blurring only lowers texture: too few textured tiles at the least blur, none at all.
      if (m->tiles_textured < options.min_textured_share * m->tiles_seen) break;
    }
    if (m->too_plain || m->tiles_used < 1) continue;
    // The collineation's standard error: fewer tiles kept by RANSAC do not make it better.
    const double error = m->tile_rms_px / std::sqrt(static_cast<double>(m->tiles_used));
    if (error < best) {
      best = error;
      out.sigma_px = candidates[i];
      out.at_best = std::move(*m);
    }
  }
  // A pick from a few tiles is too noisy to keep for the view's life.
  if (out.sigma_px && out.at_best.tiles_used < 2 * options.min_tiles) out.sigma_px.reset();
  return out;
}

}  // namespace procam::drift
