#pragma once
// The homography pre-warp (seed §4.2.1 eq. 4.6) applied straight from H, without a
// per-pixel map: along an output row the backward map is affine in x before the division,
// so eight pixels' source coordinates cost a few vector multiply-adds and one vector
// division, and no map streams from memory (a packed 1080p map is 12 MB per frame).
// Sampling is remapRgba's: the same footprint, edge clamping and 1/128 px integer weights.
// Coordinates are evaluated in float from a double anchor every eight pixels, within
// ~1e-3 px of homographyMap's double evaluation (far below the 1/256 px quantisation
// step), so the two paths differ by at most one code value in rare rounding ties.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "core/types.hpp"
#include "render/remap_rgba.hpp"

namespace procam::render {

struct HomographyWarp {
  Mat3 inverse;  // output pixel -> source pixel
  cv::Size output_size, source_size;
};

// kInvalidInput for non-finite H or empty sizes, a source smaller than 2x2 or larger than
// 2 GiB; kDegenerate when H is singular (as homographyMap).
Result<HomographyWarp> makeHomographyWarp(const Mat3& H, cv::Size output_size,
                                          cv::Size source_size);

// src: CV_8UC4 of warp.source_size (any row step); dst is (re)allocated to
// warp.output_size, CV_8UC4. Rows split across all cores. kBest runs the AVX2 kernel when
// the CPU has it; every kernel computes the same integers.
Result<void> warpHomographyRgba(const cv::Mat& src, const HomographyWarp& warp, cv::Mat& dst,
                                RemapKernel kernel = RemapKernel::kBest);

}  // namespace procam::render
