#pragma once
// How blurred the camera sees an output's frame, found from one camera frame of the
// content: the frame's light is what the projector emits, but the camera sees it through
// the projector's pixel footprint, its own lens and pixels and the resampling onto the
// framebuffer grid. Pure.
#include <optional>
#include <span>

#include "misregistration.hpp"

namespace procam::drift {

// Work pixels: none, then up to about twice the blur of a camera that resolves the work
// grid (wall_oblique's camera sees it with about 1.2).
inline constexpr double kBlurCandidates[] = {0.0, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5};

// The reference blur that makes the camera's view and the shown frame agree best, and the
// misregistration measured with it. A sharp edge compared with a blurred one moves its
// tile by up to half a pixel (crossed bands on wall_oblique: tiles scatter 0.51 px against
// the sharp frame, 0.15 px blurred by 1.25 work px), so the blur is picked from
// `candidates` by the least standard error of the tiles about their collineation
// (tile_rms_px / sqrt(tiles_used)); `sigma_px` is nullopt when every candidate found the
// frame too plain (`at_best` is then the first candidate's; with too few textured tiles
// there the others are not tried), or the best registered under twice
// options.min_tiles tiles (`at_best` is then still its measurement). kInvalidInput as
// measureMisregistration, or for no candidates, candidates not ascending or one outside [0, 8].
struct ReferenceBlur {
  std::optional<double> sigma_px;
  Misregistration at_best;
};
Result<ReferenceBlur> fitReferenceBlur(const cv::Mat& shown, const cv::Mat& camera,
                                       const cv::Mat& map, const WorkGrid& grid,
                                       const MisregistrationOptions& options = {},
                                       const cv::Mat& usable = {},
                                       std::span<const double> candidates = kBlurCandidates);

}  // namespace procam::drift
