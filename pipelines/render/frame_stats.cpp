#include "render/frame_stats.hpp"

#include <cstdint>

namespace procam::render {

Result<FrameStats> frameStats(const cv::Mat& image) {
  if (image.empty() || (image.type() != CV_8UC4 && image.type() != CV_8UC3)) {
    return fail(ErrorCode::kInvalidInput, "frame statistics need an RGB or RGBA 8-bit image");
  }
  const int channels = image.channels();
  uint64_t lit = 0;
  std::array<uint64_t, 3> sum{};
  // One pass; 64-bit sums are exact for any frame size a display has.
  for (int y = 0; y < image.rows; ++y) {
    const uint8_t* p = image.ptr<uint8_t>(y);
    for (int x = 0; x < image.cols; ++x, p += channels) {
      sum[0] += p[0];
      sum[1] += p[1];
      sum[2] += p[2];
      lit += (p[0] | p[1] | p[2]) != 0;
    }
  }
  const double n = static_cast<double>(image.total());
  FrameStats s;
  s.lit_fraction = static_cast<double>(lit) / n;
  for (int c = 0; c < 3; ++c) s.mean_rgb[c] = static_cast<double>(sum[c]) / n;
  return s;
}

}  // namespace procam::render
