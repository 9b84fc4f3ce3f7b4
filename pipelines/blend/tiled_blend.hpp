#pragma once
// Everything a planar multi-projector display needs per projector, made once per content
// size and rig ([Raskar02] §4.2.4 and §4.1.2): the display rectangle and each
// projector's homography (tiled_display.hpp), the eq. 4.3 feathering weights
// (feather.hpp) and the weight table that applies them in linear light through the
// projector's measured response and brightness gain (response.hpp). The daemon and
// procam-render make their frames from the same result.
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <vector>

#include "blend/response.hpp"
#include "blend/tiled_display.hpp"
#include "core/error.hpp"
#include "render/final_stage.hpp"

namespace procam::blend {

// The response assumed for blending until the projectors' responses are measured:
// light ~ code^2.2, the sRGB-like curve most projectors ship with.
inline constexpr double kAssumedGamma = 2.2;

struct TiledBlend {
  TiledDisplay display;
  std::vector<cv::Mat> weights;         // per tile, CV_32FC1 eq. 4.3 weights in [0, 1]
  std::vector<cv::Mat> alpha;           // per tile, CV_8UC1: round(255 weight)
  std::vector<render::Lut> weight_lut;  // per tile: weight code -> code
  std::vector<double> gamma, gain;      // per tile, what the tables were made with
  bool measured = false;                // every tile's response was measured
};

// `responses` has one entry per tile (or none): when every tile's response is known the
// projectors are matched to the dimmest one's white in linear light; otherwise every
// tile gets the assumed gamma and no gain. Errors as solveTiledDisplay and
// featherWeights; kInvalidInput for a responses count other than 0 or one per tile.
Result<TiledBlend> makeTiledBlend(std::span<const DisplayTile> tiles,
                                  std::span<const std::optional<ProjectorResponse>> responses,
                                  cv::Size content, const TiledDisplayOptions& options = {});

}  // namespace procam::blend
