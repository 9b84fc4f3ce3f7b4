#pragma once
// Single-frame sources: an image file (PNG/JPEG, any OpenCV can decode) and a
// test pattern. Each yields its frame once, then end of stream.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "content_source.hpp"

namespace procam::content {

// Images larger than this are refused unless the caller says otherwise: 32 Mpx is
// an 8K x 4K frame, 128 MiB once decoded to RGBA.
inline constexpr std::uint64_t kDefaultMaxImagePixels = std::uint64_t{1} << 25;

// Decodes now: kIo when the file cannot be read or decoded, or is under 2x2;
// kTooLarge when its header declares more than `max_pixels` (checked before
// decoding, content/image_header.hpp). Grey and 16-bit images are converted; the
// frame is RGBA.
Result<std::unique_ptr<ContentSource>> openStillImage(
    const std::string& path, std::uint64_t max_pixels = kDefaultMaxImagePixels);
// The same from the file's bytes; `origin` names it in messages.
Result<std::unique_ptr<ContentSource>> decodeStillImage(
    std::string_view bytes, const std::string& origin,
    std::uint64_t max_pixels = kDefaultMaxImagePixels);

// A named pattern from test_pattern.hpp (grid, crosshair, white, black), RGB.
Result<std::unique_ptr<ContentSource>> openTestPattern(const std::string& name, cv::Size size);

// A decoded frame as a source (what both of the above return).
std::unique_ptr<ContentSource> singleFrameSource(cv::Mat pixels, PixelFormat format);

}  // namespace procam::content
