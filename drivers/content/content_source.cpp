#include "content_source.hpp"

#include <opencv2/imgproc.hpp>

namespace procam::content {

int bytesPerPixel(PixelFormat format) {
  return format == PixelFormat::kRgb8 ? 3 : 4;
}

std::string_view toString(PixelFormat format) {
  return format == PixelFormat::kRgb8 ? "rgb8" : "rgba8";
}

Result<PixelFormat> parsePixelFormat(std::string_view name) {
  if (name == "rgb8" || name == "rgb") return PixelFormat::kRgb8;
  if (name == "rgba8" || name == "rgba") return PixelFormat::kRgba8;
  return fail(ErrorCode::kInvalidInput,
              "unknown pixel format '" + std::string(name) + "' (rgb8, rgba8)");
}

cv::Mat toRgba(const Frame& frame) {
  if (frame.pixels.type() == CV_8UC4) return frame.pixels;
  cv::Mat rgba;
  cv::cvtColor(frame.pixels, rgba, cv::COLOR_RGB2RGBA);
  return rgba;
}

}  // namespace procam::content
