#include "blend/tiled_blend.hpp"

#include <algorithm>

#include "blend/feather.hpp"

namespace procam::blend {

Result<TiledBlend> makeTiledBlend(std::span<const DisplayTile> tiles,
                                  std::span<const std::optional<ProjectorResponse>> responses,
                                  cv::Size content, const TiledDisplayOptions& options) {
  if (!responses.empty() && responses.size() != tiles.size())
    return fail(ErrorCode::kInvalidInput, "one response per tile, or none");
  TiledBlend out;
  auto display = solveTiledDisplay(tiles, content.width, content.height, options);
  if (!display) return tl::unexpected(display.error());
  std::vector<FeatherTile> feather;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    feather.push_back({display->footprints[t], display->plane_to_framebuffer[t], tiles[t].width,
                       tiles[t].height});
  }
  auto weights = featherWeights(feather);
  if (!weights) return tl::unexpected(weights.error());
  out.measured = !responses.empty() && std::all_of(responses.begin(), responses.end(),
                                                   [](const auto& r) { return r.has_value(); });
  std::vector<ProjectorResponse> measured;
  if (out.measured) {
    for (const auto& r : responses) measured.push_back(*r);
  }
  const std::vector<double> gains =
      out.measured ? matchedGains(measured) : std::vector<double>(tiles.size(), 1.0);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const double gamma = out.measured ? measured[t].gamma : kAssumedGamma;
    auto lut = weightLut(gamma, gains[t]);
    if (!lut) return tl::unexpected(lut.error());
    out.gamma.push_back(gamma);
    out.gain.push_back(gains[t]);
    out.weight_lut.push_back(*lut);
    out.alpha.push_back(alphaMask((*weights)[t]));
  }
  out.weights = std::move(*weights);
  out.display = std::move(*display);
  return out;
}

}  // namespace procam::blend
