#pragma once
// Bilinear sampling of RGBA8 images in ARCHITECTURE.md's pixel convention: pixel (i, j) has its
// centre at (i, j). A sample at (x, y) is defined on [-0.5, W-0.5) x [-0.5, H-0.5) — the
// image's footprint — with the outermost half pixel clamped to the edge texel (what GL's
// CLAMP_TO_EDGE does); outside the footprint the result is transparent black.
// This double-precision version is the specification the fast paths are tested against.
#include <opencv2/core.hpp>

namespace procam::render {

// rgba: CV_8UC4. Returns channel values in [0, 255] (not rounded).
cv::Vec4d sampleBilinear(const cv::Mat& rgba, double x, double y);

// True when (x, y) lies inside the footprint of a width x height image.
inline bool insideFootprint(double x, double y, int width, int height) {
  return x >= -0.5 && y >= -0.5 && x < width - 0.5 && y < height - 0.5;
}

}  // namespace procam::render
