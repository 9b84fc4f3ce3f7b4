#pragma once
// Single-frame sources: an image file (PNG/JPEG, any OpenCV can decode) and a
// test pattern. Each yields its frame once, then end of stream.
#include <memory>
#include <string>

#include "content_source.hpp"

namespace procam::content {

// Decodes now: kIo when the file cannot be read or decoded, or is under 2x2.
// Grey and 16-bit images are converted; the frame is RGBA.
Result<std::unique_ptr<ContentSource>> openStillImage(const std::string& path);

// A named pattern from test_pattern.hpp (grid, crosshair, white, black), RGB.
Result<std::unique_ptr<ContentSource>> openTestPattern(const std::string& name, cv::Size size);

// A decoded frame as a source (what both of the above return).
std::unique_ptr<ContentSource> singleFrameSource(cv::Mat pixels, PixelFormat format);

}  // namespace procam::content
