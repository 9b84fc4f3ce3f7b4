#include "render/packed_map.hpp"

#include <algorithm>
#include <cmath>

#include "render/bilinear.hpp"

namespace procam::render {

Result<PackedMap> packMap(const WarpMap& map, cv::Size source_size, int source_step) {
  if (map.xy.empty() || map.xy.type() != CV_32FC2) {
    return fail(ErrorCode::kInvalidInput, "packMap: empty or non-CV_32FC2 map");
  }
  if (source_size.width < 2 || source_size.height < 2) {
    return fail(ErrorCode::kInvalidInput, "packMap: source must be at least 2x2 pixels");
  }
  if (source_step == 0) source_step = 4 * source_size.width;
  if (source_step < 4 * source_size.width ||
      static_cast<double>(source_step) * source_size.height > 2147483647.0) {
    return fail(ErrorCode::kInvalidInput, "packMap: row step shorter than a row or image > 2 GiB");
  }
  PackedMap out;
  out.output_size = map.xy.size();
  out.source_size = source_size;
  out.source_step = source_step;
  const size_t n = static_cast<size_t>(out.output_size.area());
  out.offset.assign(n, -1);
  out.fx.assign(n, 0);
  out.fy.assign(n, 0);
  const int w = source_size.width, h = source_size.height;
  // One axis: top-left texel index and quantised weight of the next texel. The outer half
  // pixel of the footprint clamps to the edge texel (see bilinear.hpp).
  // v lies in the footprint, [-0.5, size - 0.5): the integer floor without a libm call,
  // and v - floor(v) in [0, 1) times a power of two plus a half is exact in double (v came
  // from a float), so truncation rounds half up as lround does; a handheld projector's
  // keystone packs a new map every frame.
  auto axis = [](double v, int size, int& i0, uint8_t& f) {
    int i = static_cast<int>(v);
    if (static_cast<double>(i) > v) --i;
    const double fl = static_cast<double>(i);
    int q = static_cast<int>((v - fl) * kSubpixelOne + 0.5);
    if (q == kSubpixelOne) {
      ++i;
      q = 0;
    }
    if (i < 0) {
      i = 0;
      q = 0;
    } else if (i >= size - 1) {
      i = size - 2;  // weight all on the last texel
      q = kSubpixelOne;
    }
    i0 = i;
    f = static_cast<uint8_t>(q);
  };
  // Rows on all threads, as the map itself (warp_map.cpp).
  cv::parallel_for_(cv::Range(0, out.output_size.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const auto* row = map.xy.ptr<cv::Vec2f>(y);
      for (int x = 0; x < out.output_size.width; ++x) {
        const double sx = row[x][0], sy = row[x][1];
        if (!insideFootprint(sx, sy, w, h)) continue;
        const size_t k = static_cast<size_t>(y) * out.output_size.width + x;
        int x0 = 0, y0 = 0;
        axis(sx, w, x0, out.fx[k]);
        axis(sy, h, y0, out.fy[k]);
        out.offset[k] = y0 * source_step + 4 * x0;
      }
    }
  });
  return out;
}

}  // namespace procam::render
