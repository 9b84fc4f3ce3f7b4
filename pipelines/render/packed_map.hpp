#pragma once
// A warp map compiled for one source-image size: per output pixel the index of the
// top-left texel of its 2x2 bilinear footprint and the sub-pixel position in 1/128 px.
// Compiling moves every branch (footprint test, edge clamping) out of the per-frame loop.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/error.hpp"
#include "render/warp_map.hpp"

namespace procam::render {

inline constexpr int kSubpixelBits = 7;  // weights in 1/128: 255 * 128^2 fits int32 sums
inline constexpr int kSubpixelOne = 1 << kSubpixelBits;

struct PackedMap {
  cv::Size output_size;
  cv::Size source_size;
  int source_step = 0;          // source row length in bytes the offsets were made for
  std::vector<int32_t> offset;  // byte offset y0 * step + 4 * x0, or -1 when outside
  std::vector<uint8_t> fx, fy;  // 0..128 weight of the right / lower texel
};

// source_step: bytes per source row (cv::Mat::step); 0 means 4 * source_size.width.
// kInvalidInput for an empty map, a source smaller than 2x2 or larger than 2 GiB.
Result<PackedMap> packMap(const WarpMap& map, cv::Size source_size, int source_step = 0);

}  // namespace procam::render
