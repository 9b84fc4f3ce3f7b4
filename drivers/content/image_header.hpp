#pragma once
// The pixel size an image file declares, read from its header alone, so that a
// decoder is never started on an image too large to hold: a few bytes of PNG can
// declare 30000x30000 pixels (3.6 GB once decoded).
#include <string_view>

#include "content_source.hpp"

namespace procam::content {

struct ImageHeader {
  const char* format = "";  // "png", "jpeg", "bmp", "pnm", "webp", "tiff"
  cv::Size size;
};

// kInvalidInput for a format procamd does not read or a header that does not parse
// (a truncated one included): only what is named above is decoded.
Result<ImageHeader> readImageHeader(std::string_view bytes);

}  // namespace procam::content
