#pragma once
// The last stage of every projector frame ([Raskar02] §4.1.2): a per-pixel intensity weight
// from the projector's alpha mask, itself passed through a lookup table that accounts for
// the projector's non-linear response (so blended overlaps sum to one in light, not in
// code values), then a per-channel output lookup table. Integer arithmetic defined here
// exactly; the GL back-end reproduces it bit for bit.
//   w   = weight_lut[alpha]
//   v_c = (c * w + 127) / 255           (c = R, G, B; alpha channel untouched)
//   out = output_lut[c][v_c]
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

#include "core/error.hpp"

namespace procam::render {

using Lut = std::array<uint8_t, 256>;

struct FinalStage {
  cv::Mat alpha;                   // CV_8UC1 of the output size; empty = all 255
  Lut weight_lut = identityLut();  // alpha code -> weight code
  std::array<Lut, 3> output_lut = {identityLut(), identityLut(), identityLut()};

  static Lut identityLut();
  bool isIdentity() const;
};

// Same mask (by value) and lookup tables.
bool sameStage(const FinalStage& a, const FinalStage& b);

// weight_lut for a projector whose light output goes as code^gamma: weight a maps to
// 255 * (a/255)^(1/gamma), so emitted light scales with a. kInvalidInput unless gamma > 0.
Result<Lut> weightLutForGamma(double gamma);

// In place on a CV_8UC4 image of the alpha mask's size (any size when the mask is empty).
Result<void> applyFinalStage(const FinalStage& stage, cv::Mat& rgba);

}  // namespace procam::render
