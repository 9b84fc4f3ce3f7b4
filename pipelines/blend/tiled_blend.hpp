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

#include "blend/blend_tables.hpp"
#include "blend/tiled_display.hpp"
#include "core/error.hpp"

namespace procam::blend {

struct TiledBlend : BlendTables {
  TiledDisplay display;
};

// `responses` has one entry per tile (or none): when every tile's response is known the
// projectors are matched to the dimmest one's white in linear light; otherwise every
// tile gets the assumed gamma and no gain. Errors as solveTiledDisplay and
// featherWeights; kInvalidInput for a responses count other than 0 or one per tile.
Result<TiledBlend> makeTiledBlend(std::span<const DisplayTile> tiles,
                                  std::span<const std::optional<ProjectorResponse>> responses,
                                  cv::Size content, const TiledDisplayOptions& options = {});

}  // namespace procam::blend
