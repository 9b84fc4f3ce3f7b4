#pragma once
// A few numbers about a projector frame, so that status can say what an output shows
// without sending the frame: the fraction of lit pixels and the mean colour.
#include <array>
#include <opencv2/core.hpp>

#include "core/error.hpp"

namespace procam::render {

struct FrameStats {
  double lit_fraction = 0;           // pixels with any of R, G, B above 0
  std::array<double, 3> mean_rgb{};  // 0..255
};

// CV_8UC4 (RGBA, alpha ignored) or CV_8UC3 (RGB); kInvalidInput for other types or
// an empty image.
Result<FrameStats> frameStats(const cv::Mat& image);

}  // namespace procam::render
