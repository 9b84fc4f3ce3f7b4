#pragma once
// A projector's frame for shader lamps: the appearance rendered from the projector's
// view and radiance-corrected per pixel ([Raskar02] eq. 5.4),
//   I_P(x) = w(x) · L(x) · d(x)² / (k(x) · B · cos θ_P),
// w the projector's feathering weight (lamp_weights.hpp), k·B the light the neutral
// object returns per unit of the projector's intensity at 1 m and normal incidence
// (its diffuse reflectance times the projector's brightness: measured), then through the
// inverse of the projector's response into code values. Pixels that do not light the
// object stay black, so no light reaches past its silhouette.
#include <opencv2/core.hpp>
#include <optional>
#include <span>

#include "core/error.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/lamp_view.hpp"

namespace procam::lamps {

struct LampPhotometry {
  double gamma = 2.2;            // code value c -> light (c / 255)^gamma
  Vec3 gain_rgb = Vec3::Ones();  // k · B per channel, in the radiance units of L
};

struct LampFrameStats {
  long lit_pixels = 0;      // pixels with a weight above zero
  long clipped_pixels = 0;  // of those, pixels whose I_P exceeded full white in a channel
};

struct LampFrameInput {
  const LampView* view = nullptr;
  const cv::Mat* weight = nullptr;  // CV_32FC1, the view's size
  LampPhotometry photometry;
};

// kInvalidInput for a missing view or weight, mismatched sizes, a gamma outside [1, 4] or
// a gain that is not finite and positive.
Result<void> checkLampInput(const LampFrameInput& lamp);

// The brightest white level (radiance of a white texel, L = 1) that every projector can
// give at every point it lights with its weight: the smallest k·B·cos θ / (w · d²) over
// lit pixels and channels. kNotFound when no pixel lights the object.
Result<double> lampWhiteLevel(std::span<const LampFrameInput> lamps);

// The frame, BGR, the view's size: CV_8UC3, or CV_16UC3 with `bit_depth` 16. `white`:
// the radiance of L = 1 (> 0); `eye`: the viewer, for the view-dependent (specular)
// part. kInvalidInput for a missing view or weight, mismatched sizes, a white level or
// gain that is not finite and positive, a gamma outside [1, 4], a bit depth other than 8
// or 16 or a bad material.
Result<cv::Mat> lampFrame(const LampFrameInput& lamp, const Material& material, double white,
                          const std::optional<Vec3>& eye, LampFrameStats* stats = nullptr,
                          int bit_depth = 8);

}  // namespace procam::lamps
