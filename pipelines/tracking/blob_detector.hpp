#pragma once
// IR LED blobs in an IR-filtered camera image: background subtraction,
// threshold, 8-connected components, intensity-weighted sub-pixel centroids.
// Pixel centres are at integer coordinates (ARCHITECTURE.md).
#include <opencv2/core/mat.hpp>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::tracking {

struct BlobOptions {
  double threshold = 40;  // in image units above the background (8 or 16 bit)
  int min_area = 2;       // pixels above the threshold
  int max_area = 2000;
  double max_elongation = 4;  // sqrt(major / minor second moment)
  int max_blobs = 32;         // strongest kept
};

struct Blob {
  Vec2 center = Vec2::Zero();  // centroid weighted by value - threshold, pixels
  int area = 0;                // pixels above the threshold
  double intensity = 0;        // sum of (background-subtracted value - threshold)
  double elongation = 1;
};

// `image` is CV_8UC1 or CV_16UC1; `background` empty or the same size and type (e.g.
// a frame with the LEDs off). Blobs come out strongest first. kInvalidInput for other
// types, size mismatch or bad options.
Result<std::vector<Blob>> detectBlobs(const cv::Mat& image, const cv::Mat& background,
                                      const BlobOptions& options);

}  // namespace procam::tracking
