#include "blend/blend_tables.hpp"

#include <algorithm>

#include "blend/feather.hpp"

namespace procam::blend {

Result<BlendTables> blendTables(std::vector<cv::Mat> weights,
                                std::span<const std::optional<ProjectorResponse>> responses,
                                std::span<const ContentOf> to_content, cv::Size content) {
  if (!responses.empty() && responses.size() != weights.size())
    return fail(ErrorCode::kInvalidInput, "one response per projector, or none");
  if (!to_content.empty() && to_content.size() != weights.size())
    return fail(ErrorCode::kInvalidInput, "one content map per projector, or none");
  for (const cv::Mat& w : weights) {
    if (w.type() != CV_32FC1 || w.empty())
      return fail(ErrorCode::kInvalidInput, "blend weights must be non-empty CV_32FC1 images");
  }
  BlendTables out;
  out.measured = !responses.empty() && std::all_of(responses.begin(), responses.end(),
                                                   [](const auto& r) { return r.has_value(); });
  std::vector<ProjectorResponse> measured;
  if (out.measured) {
    for (const auto& r : responses) measured.push_back(*r);
  }
  out.different_cameras =
      out.measured && std::any_of(measured.begin(), measured.end(), [&](const auto& r) {
        return r.camera != measured.front().camera;
      });
  const bool comparable = out.measured && !out.different_cameras;
  const bool per_pixel =
      comparable && !to_content.empty() &&
      std::all_of(measured.begin(), measured.end(), [](const auto& r) { return r.brightness; });
  if (per_pixel) {
    std::vector<MatchProjector> match;
    for (std::size_t t = 0; t < weights.size(); ++t)
      match.push_back({&weights[t], &*measured[t].brightness, to_content[t]});
    auto matched = matchLuminance(match, content);
    if (!matched) return tl::unexpected(matched.error());
    weights = std::move(matched->weights);
    out.matched = matched->figures;
  }
  const std::vector<double> gains =
      comparable && !per_pixel ? matchedGains(measured) : std::vector<double>(weights.size(), 1.0);
  for (std::size_t t = 0; t < weights.size(); ++t) {
    const double gamma = out.measured ? measured[t].gamma : kAssumedGamma;
    auto lut = weightLut(gamma, gains[t]);
    if (!lut) return tl::unexpected(lut.error());
    out.gamma.push_back(gamma);
    out.gain.push_back(gains[t]);
    out.weight_lut.push_back(*lut);
    out.alpha.push_back(alphaMask(weights[t]));
  }
  out.weights = std::move(weights);
  return out;
}

nlohmann::json matchingJson(const BlendTables& tables) {
  if (!tables.measured) return {{"matching", "none"}};
  if (tables.different_cameras)
    return {{"matching", "none"}, {"why", "the responses were measured by different cameras"}};
  if (!tables.matched) return {{"matching", "per-projector gain"}};
  const LuminanceFigures& f = *tables.matched;
  const auto ratio = [](double lo, double hi) { return hi > 0 ? lo / hi : 0.0; };
  return {{"matching", "per-pixel"},
          {"uniformity_before", ratio(f.before_min, f.before_max)},
          {"uniformity_after", ratio(f.after_min, f.after_max)},
          {"light_kept", f.kept},
          {"largest_step_per_px", f.largest_step}};
}

}  // namespace procam::blend
