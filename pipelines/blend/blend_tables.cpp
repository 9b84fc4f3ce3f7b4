#include "blend/blend_tables.hpp"

#include <algorithm>

#include "blend/feather.hpp"

namespace procam::blend {

Result<BlendTables> blendTables(std::vector<cv::Mat> weights,
                                std::span<const std::optional<ProjectorResponse>> responses) {
  if (!responses.empty() && responses.size() != weights.size())
    return fail(ErrorCode::kInvalidInput, "one response per projector, or none");
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
  const std::vector<double> gains =
      out.measured ? matchedGains(measured) : std::vector<double>(weights.size(), 1.0);
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

}  // namespace procam::blend
