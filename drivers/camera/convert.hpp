#pragma once
// Conversion of what devices send (V4L2 fourccs, GenICam pixel formats, image files) into
// the pipeline's formats, done once per frame. Formats the pipeline already uses are
// wrapped without a copy when the caller keeps the source alive (zero copy).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "camera/camera.hpp"

namespace procam::camera {

enum class SourceFormat {
  kGrey,   // 8-bit mono (V4L2 GREY, GenICam Mono8)
  kY16,    // 16-bit little-endian mono (V4L2 Y16, GenICam Mono16)
  kYuyv,   // YUV 4:2:2 packed Y0 U Y1 V
  kMjpeg,  // one JPEG per frame (V4L2 MJPG)
  kRgb24,  // R G B
  kBgr24,  // B G R
};

const char* toString(SourceFormat format);
// The pipeline format a source becomes when nothing else is asked: mono stays mono,
// colour becomes RGB8.
procam_pixel_format naturalPixel(SourceFormat format);
// "gray8", "gray16", "rgb8".
std::optional<procam_pixel_format> parsePixel(const std::string& text);
const char* toString(procam_pixel_format pixel);

struct SourceImage {
  SourceFormat format;
  const uint8_t* data;
  std::size_t bytes;  // bytes used (MJPEG: the compressed size)
  uint32_t width;
  uint32_t height;
  uint32_t stride;  // bytes per row; ignored for MJPEG
};

// Fills `out.image` and `out.pixel` with `src` in format `want`. With `zero_copy`, a
// source already in `want` is wrapped, not copied (the caller keeps it alive for the
// frame's lifetime); otherwise the result lands in `storage`, reused across frames.
// kInvalid for a truncated buffer, a JPEG that does not decode, or an impossible
// conversion (16-bit from 8-bit colour).
Result<void> convertFrame(const SourceImage& src, procam_pixel_format want, bool zero_copy,
                          cv::Mat& storage, Frame& out);

}  // namespace procam::camera
