#include "shader_lamps/lamp_frame.hpp"

#include <atomic>
#include <cmath>
#include <opencv2/core/utility.hpp>

namespace procam::lamps {

Result<void> checkLampInput(const LampFrameInput& l) {
  if (!l.view || !l.weight || l.view->face.empty())
    return fail(ErrorCode::kInvalidInput, "a projector has no view or weights");
  if (l.weight->size() != l.view->size || l.weight->type() != CV_32FC1)
    return fail(ErrorCode::kInvalidInput, "a projector's weights do not match its view");
  if (!(l.photometry.gamma >= 1 && l.photometry.gamma <= 4))
    return fail(ErrorCode::kInvalidInput, "a projector's gamma must lie in [1, 4]");
  if (!l.photometry.gain_rgb.allFinite() || !(l.photometry.gain_rgb.minCoeff() > 0))
    return fail(ErrorCode::kInvalidInput, "a projector's gain must be finite and positive");
  return {};
}

Result<double> lampWhiteLevel(std::span<const LampFrameInput> lamps) {
  double best = std::numeric_limits<double>::infinity();
  for (const LampFrameInput& l : lamps) {
    if (auto ok = checkLampInput(l); !ok) return tl::unexpected(ok.error());
    const double gain = l.photometry.gain_rgb.minCoeff();
    for (int y = 0; y < l.view->size.height; ++y) {
      for (int x = 0; x < l.view->size.width; ++x) {
        const double w = l.weight->at<float>(y, x);
        if (!(w > 0)) continue;
        const double d = l.view->distance.at<float>(y, x);
        const double c = l.view->cosine.at<float>(y, x);
        best = std::min(best, gain * c / (w * d * d));
      }
    }
  }
  if (!std::isfinite(best) || !(best > 0))
    return fail(ErrorCode::kNotFound, "no projector lights the object");
  return best;
}

Result<cv::Mat> lampFrame(const LampFrameInput& l, const Material& material, double white,
                          const std::optional<Vec3>& eye, LampFrameStats* stats, int bit_depth) {
  if (bit_depth != 8 && bit_depth != 16)
    return fail(ErrorCode::kInvalidInput, "frames are 8 or 16 bits deep");
  if (auto ok = checkLampInput(l); !ok) return tl::unexpected(ok.error());
  if (auto ok = checkMaterial(material); !ok) return tl::unexpected(ok.error());
  if (!(std::isfinite(white) && white > 0))
    return fail(ErrorCode::kInvalidInput, "the white level must be finite and positive");
  if (eye && !eye->allFinite()) return fail(ErrorCode::kInvalidInput, "the eye is not finite");
  const LampView& v = *l.view;
  cv::Mat frame(v.size, bit_depth == 8 ? CV_8UC3 : CV_16UC3, cv::Scalar::all(0));
  const double top = bit_depth == 8 ? 255 : 65535;
  const double inv_gamma = 1 / l.photometry.gamma;
  const Vec3 gain = l.photometry.gain_rgb;
  std::atomic<long> lit{0}, clipped{0};
  cv::parallel_for_(cv::Range(0, v.size.height), [&](const cv::Range& rows) {
    long row_lit = 0, row_clipped = 0;
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < v.size.width; ++x) {
        const double w = l.weight->at<float>(y, x);
        if (!(w > 0)) continue;
        const cv::Vec3f& p = v.point.at<cv::Vec3f>(y, x);
        const cv::Vec3f& n = v.normal.at<cv::Vec3f>(y, x);
        const cv::Vec2f& t = v.texcoord.at<cv::Vec2f>(y, x);
        const Vec3 L = white * desiredRadiance(material, Vec3(p[0], p[1], p[2]),
                                               Vec3(n[0], n[1], n[2]), Vec2(t[0], t[1]), eye);
        const double d = v.distance.at<float>(y, x), c = v.cosine.at<float>(y, x);
        // eq. 5.4 with the weight: the share of L this projector gives.
        const Vec3 I = (w * d * d / c) * L.cwiseQuotient(gain);
        ++row_lit;
        row_clipped += I.maxCoeff() > 1 + 1e-6;
        for (int k = 0; k < 3; ++k) {
          const double code = top * std::pow(std::clamp(I[k], 0.0, 1.0), inv_gamma);
          if (bit_depth == 8)
            frame.at<cv::Vec3b>(y, x)[2 - k] = static_cast<std::uint8_t>(std::lround(code));
          else
            frame.at<cv::Vec3w>(y, x)[2 - k] = static_cast<std::uint16_t>(std::lround(code));
        }
      }
    }
    lit += row_lit;
    clipped += row_clipped;
  });
  if (stats) {
    stats->lit_pixels = lit;
    stats->clipped_pixels = clipped;
  }
  return frame;
}

}  // namespace procam::lamps
