#pragma once
// Photometric matching per pixel ([Majumder05]: A. Majumder, R. Stevens, "Perceptual
// photometric seamlessness in projection-based tiled displays", ACM TOG 24(1), 2005):
// every projector lights its eq. 4.3 share w of a target white T at each content point,
// scaled by its measured brightness L there (brightness_map.hpp): weight T w / L, so
// the light of every point sums to T wherever the weights sum to one. T is the
// brightest surface the projectors reach (T <= L / w for each projector lighting the
// point) that changes by no more than a given fraction per content pixel, computed in
// log luminance as T(x) = min_y (log B(y) + g |x - y|) by two chamfer passes on a raster
// of the content; no overlap band is then brighter or darker than its neighbours.
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "blend/brightness_map.hpp"
#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::blend {

// A framebuffer pixel's content pixel, or nullopt where the projector shows no content;
// called from several threads at once.
using ContentOf = std::function<std::optional<Vec2>(const Vec2& pixel)>;

struct MatchProjector {
  const cv::Mat* weights = nullptr;           // CV_32FC1 framebuffer: eq. 4.3 weights
  const BrightnessMap* brightness = nullptr;  // of the same framebuffer size
  ContentOf to_content;
};

struct LuminanceMatchOptions {
  int cells = 160;  // raster cells along the content's longer side, in [16, 2048]
  // The target's largest change per content pixel, as a fraction of its value
  // ([Majumder05] bounds the gradient so that it stays unnoticed; this default is a
  // choice, not their measured threshold): 0.02 % is 0.6 % per degree of view for 1920
  // content pixels across 60 degrees, and flatter than a projector's own cos θ / d²
  // fall-off near its frame's edge (about 0.03 % per pixel for a 1280-pixel frame 1.5 m
  // from the wall).
  double gradient_per_px = 2e-4;
  int sample_step = 2;  // framebuffer pixels between the samples of the display luminance
};

// Over the content raster, in the brightness maps' units: the display's white before
// matching (the eq. 4.3 weights at full brightness) and after (T); min / max is its
// uniformity; `kept` is the mean of T over the mean before.
struct LuminanceFigures {
  double before_min = 0, before_max = 0, after_min = 0, after_max = 0;
  double kept = 0;
  double largest_step = 0;  // of T between neighbouring raster cells, per content pixel
};

struct LuminanceMatch {
  std::vector<cv::Mat> weights;  // per projector, CV_32FC1: T w / L
  LuminanceFigures figures;
};

// kInvalidInput for no projectors, a missing or mismatched weight image or brightness
// map, a missing content function, an empty content size or options out of range;
// kNotFound when no projector pixel lands on the content.
Result<LuminanceMatch> matchLuminance(std::span<const MatchProjector> projectors, cv::Size content,
                                      const LuminanceMatchOptions& options = {});

}  // namespace procam::blend
