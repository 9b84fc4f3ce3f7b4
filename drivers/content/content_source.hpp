#pragma once
// Content sources: where the frames an output shows come from (still images, raw
// frames from a file or FIFO, test patterns, shared memory, video). The daemon
// polls `pollFd()` when there is one, otherwise asks every `frameInterval()`, and
// calls read() until it reports no new frame.
#include <chrono>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string_view>

#include "core/error.hpp"

namespace procam::content {

enum class PixelFormat { kRgb8, kRgba8 };

int bytesPerPixel(PixelFormat format);
std::string_view toString(PixelFormat format);
// "rgb8"/"rgb" and "rgba8"/"rgba"; kInvalidInput otherwise.
Result<PixelFormat> parsePixelFormat(std::string_view name);

struct Frame {
  cv::Mat pixels;  // CV_8UC3 (RGB) or CV_8UC4 (RGBA), R first; owns its bytes
  PixelFormat format = PixelFormat::kRgba8;
  std::chrono::nanoseconds timestamp{0};  // source clock; 0 for a still
  uint64_t sequence = 0;                  // 1 for the first frame, +1 per frame read
};

enum class ReadStatus {
  kFrame,    // `out` holds a new frame
  kNoFrame,  // nothing new yet; poll again
  kEnd,      // clean end of stream: keep showing the last frame
};

class ContentSource {
 public:
  virtual ~ContentSource() = default;
  virtual cv::Size size() const = 0;
  virtual PixelFormat format() const = 0;
  // Readable when a frame may be ready; -1 when the source is paced by
  // frameInterval() instead (or produces a single frame).
  virtual int pollFd() const { return -1; }
  virtual std::optional<std::chrono::nanoseconds> frameInterval() const { return std::nullopt; }
  // Errors end the stream too (a partial frame, a read error, a bad file).
  virtual Result<ReadStatus> read(Frame& out) = 0;
};

// Converts a frame to the daemon's content representation (CV_8UC4 RGBA).
cv::Mat toRgba(const Frame& frame);

}  // namespace procam::content
