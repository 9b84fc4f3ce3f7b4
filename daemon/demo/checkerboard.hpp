#pragma once
// The demo's projected target: a checkerboard with a white quiet zone, drawn at
// projector resolution, and the framebuffer positions of its inner corners.
#include <opencv2/core.hpp>

#include "core/types.hpp"

namespace procam::demo {

struct Checkerboard {
  cv::Mat image;          // CV_8UC1, projector resolution
  cv::Size inner;         // inner corners per row and column
  Points2 corners;        // framebuffer coordinates, row by row (pixel-centre convention)
};

// Squares of `square` pixels, centred, one square of white margin at least.
Checkerboard makeCheckerboard(int width, int height, int square);

}  // namespace procam::demo
