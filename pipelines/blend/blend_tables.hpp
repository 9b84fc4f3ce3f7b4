#pragma once
// What an output needs to blend ([Raskar02] §4.1.2): per projector its eq. 4.3 weights
// as an 8-bit alpha mask and the table that turns a weight into a code value through the
// projector's response and its brightness gain (response.hpp). Shared by the planar
// tiled display and the curved one.
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <vector>

#include "blend/luminance_match.hpp"
#include "blend/response.hpp"
#include "core/error.hpp"
#include "render/final_stage.hpp"

namespace procam::blend {

// The response assumed for blending until the projectors' responses are measured:
// light ~ code^2.2, the sRGB-like curve most projectors ship with.
inline constexpr double kAssumedGamma = 2.2;

struct BlendTables {
  std::vector<cv::Mat> weights;         // per projector, CV_32FC1 eq. 4.3 weights in [0, 1]
  std::vector<cv::Mat> alpha;           // per projector, CV_8UC1: round(255 weight)
  std::vector<render::Lut> weight_lut;  // per projector: weight code -> code
  std::vector<double> gamma, gain;      // per projector, what the tables were made with
  bool measured = false;                // every projector's response was measured
  // Matched per pixel ([Majumder05], luminance_match.hpp): the weights carry each
  // point's attenuation to the display's smooth target and every gain is 1.
  std::optional<LuminanceFigures> matched;
  // Responses measured by different cameras: their brightness does not compare, so the
  // projectors are not matched (each keeps its response, no gain).
  bool different_cameras = false;
};

// `responses` has one entry per weight image (or none): when every projector's response
// and its brightness across the frame are known and `to_content` gives each projector's
// content map, the projectors are matched per pixel (luminance_match.hpp) into `content`;
// when every response is known, to the dimmest one's white in linear light (neither
// when different cameras measured them: each keeps its response, no gain); otherwise
// every one gets the assumed gamma and no gain. kInvalidInput for a responses or
// to_content count other than 0 or one per weight image, or weights that are not
// CV_32FC1; errors of matchLuminance.
Result<BlendTables> blendTables(std::vector<cv::Mat> weights,
                                std::span<const std::optional<ProjectorResponse>> responses,
                                std::span<const ContentOf> to_content = {}, cv::Size content = {});

// How the tables match the projectors, for status and display.json: {"matching":
// "per-pixel", "uniformity_before", "uniformity_after" (min / max of the display's
// white), "light_kept", "largest_step_per_px"}, {"matching": "per-projector gain"} or
// {"matching": "none"} (responses assumed).
nlohmann::json matchingJson(const BlendTables& tables);

}  // namespace procam::blend
