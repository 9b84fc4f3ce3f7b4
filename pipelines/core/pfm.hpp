#pragma once
// Portable float maps (PFM): "PF" (3 channels) or "Pf" (1 channel), width and height, a
// scale whose sign gives the byte order (negative: little-endian), then 32-bit floats
// with the bottom row first. Encoding and decoding in memory; the callers do the I/O.
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace procam {

// `image`: CV_32FC1 or CV_32FC3, rows top to bottom; written little-endian.
Result<std::string> encodePfm(const cv::Mat& image);

// CV_32FC1 or CV_32FC3, rows top to bottom. kParse for a malformed header, a body
// shorter than the header says or a sample that is not finite; kTooLarge above
// `max_pixels`.
Result<cv::Mat> decodePfm(std::string_view bytes, double max_pixels = 1 << 26);

}  // namespace procam
