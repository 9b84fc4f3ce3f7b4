#pragma once
// Per-frame application of a packed warp map to an RGBA8 image: integer bilinear
// interpolation, rows split across all cores. The SIMD kernels (x86-64: AVX2 when the CPU
// has it, else SSE2) and the portable scalar kernel compute the same integers.
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "render/packed_map.hpp"

namespace procam::render {

// kBest: the fastest kernel this CPU runs; kSse2: the SSE2 one (scalar off x86-64).
enum class RemapKernel { kBest, kSse2, kScalar };

// src: CV_8UC4 of map.source_size with row step map.source_step; dst is (re)allocated
// to map.output_size, CV_8UC4. kInvalidInput on a size or row-step mismatch.
Result<void> remapRgba(const cv::Mat& src, const PackedMap& map, cv::Mat& dst,
                       RemapKernel kernel = RemapKernel::kBest);

// One output row of a packed map (PackedMap's layout): width entries each.
struct PackedRow {
  const int32_t* offset;
  const uint8_t* fx;
  const uint8_t* fy;
};
// Writes width RGBA8 pixels to out; the source and its step as for remapRgba.
using RemapRowFn = void (*)(const uint8_t* src, size_t src_step, const PackedRow& row, int width,
                            uint8_t* out);
RemapRowFn remapRowKernel(RemapKernel kernel);

}  // namespace procam::render
