#include "render/final_stage.hpp"

#include <cmath>
#include <cstring>

namespace procam::render {

Lut FinalStage::identityLut() {
  Lut lut{};
  for (int i = 0; i < 256; ++i) lut[i] = static_cast<uint8_t>(i);
  return lut;
}

bool sameStage(const FinalStage& a, const FinalStage& b) {
  if (a.weight_lut != b.weight_lut || a.output_lut != b.output_lut) return false;
  if (a.alpha.empty() || b.alpha.empty()) return a.alpha.empty() == b.alpha.empty();
  if (a.alpha.size() != b.alpha.size() || a.alpha.type() != b.alpha.type()) return false;
  // One buffer (a mask kept and handed to every plan, as a tiled display's is): equal
  // without reading its megabyte on every refresh.
  if (a.alpha.data == b.alpha.data && a.alpha.step == b.alpha.step) return true;
  for (int y = 0; y < a.alpha.rows; ++y) {
    if (std::memcmp(a.alpha.ptr(y), b.alpha.ptr(y), a.alpha.cols * a.alpha.elemSize()) != 0) {
      return false;
    }
  }
  return true;
}

bool FinalStage::isIdentity() const {
  const Lut id = identityLut();
  return alpha.empty() && weight_lut == id && output_lut[0] == id && output_lut[1] == id &&
         output_lut[2] == id;
}

Result<Lut> weightLutForGamma(double gamma) {
  if (!(gamma > 0) || !std::isfinite(gamma)) {
    return fail(ErrorCode::kInvalidInput, "weightLutForGamma: gamma must be finite and > 0");
  }
  Lut lut{};
  for (int i = 0; i < 256; ++i) {
    lut[i] = static_cast<uint8_t>(std::lround(255.0 * std::pow(i / 255.0, 1.0 / gamma)));
  }
  return lut;
}

Result<void> applyFinalStage(const FinalStage& stage, cv::Mat& rgba) {
  if (rgba.type() != CV_8UC4) return fail(ErrorCode::kInvalidInput, "applyFinalStage: not RGBA8");
  const bool masked = !stage.alpha.empty();
  if (masked && (stage.alpha.type() != CV_8UC1 || stage.alpha.size() != rgba.size())) {
    return fail(ErrorCode::kInvalidInput, "applyFinalStage: alpha mask not CV_8UC1 of frame size");
  }
  if (stage.isIdentity()) return {};
  // Fold weight and output tables per weight value: out = table[w][c] for each channel.
  cv::parallel_for_(cv::Range(0, rgba.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      uint8_t* p = rgba.ptr<uint8_t>(y);
      const uint8_t* a = masked ? stage.alpha.ptr<uint8_t>(y) : nullptr;
      for (int x = 0; x < rgba.cols; ++x, p += 4) {
        const int w = stage.weight_lut[a ? a[x] : 255];
        for (int c = 0; c < 3; ++c) {
          p[c] = stage.output_lut[c][(p[c] * w + 127) / 255];
        }
      }
    }
  });
  return {};
}

}  // namespace procam::render
