#pragma once
// Per-frame application of a packed warp map to an RGBA8 image: integer bilinear
// interpolation, rows split across all cores. The SIMD kernel (SSE2 on x86-64) and the
// portable scalar kernel compute the same integers.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "render/packed_map.hpp"

namespace procam::render {

enum class RemapKernel { kBest, kScalar };

// src: CV_8UC4 of map.source_size with row step map.source_step; dst is (re)allocated
// to map.output_size, CV_8UC4. kInvalidInput on a size or row-step mismatch.
Result<void> remapRgba(const cv::Mat& src, const PackedMap& map, cv::Mat& dst,
                       RemapKernel kernel = RemapKernel::kBest);

}  // namespace procam::render
