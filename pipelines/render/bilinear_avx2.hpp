#pragma once
// AVX2 building blocks of the packed-map remap (remap_rgba.cpp). Compiled for AVX2 per
// function (target attribute) so the rest of the build stays baseline x86-64; callers check
// __builtin_cpu_supports("avx2") first.
// Arithmetic (packed_map.hpp's 1/128 px weights): the horizontal blend
// p0 * (128 - fx) + p1 * fx <= 255 * 128 fits a 16-bit lane; the vertical one
// top * (128 - fy) + bottom * fy goes through madd in 32 bits, then (v + 2^13) >> 14: the
// same integers as the scalar kernel.
#if defined(__x86_64__)
#include <immintrin.h>

#include <cstdint>

#include "render/packed_map.hpp"

#define PROCAM_AVX2 __attribute__((target("avx2")))
// Forced: GCC otherwise keeps these out of line, passing every vector through the stack.
#define PROCAM_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

namespace procam::render::avx2 {

inline constexpr int kShift = 2 * kSubpixelBits;
inline constexpr int kRound = 1 << (kShift - 1);

PROCAM_AVX2_INLINE __m256i blendX(__m256i ix, __m256i fx, __m256i p0, __m256i p1) {
  return _mm256_add_epi16(_mm256_mullo_epi16(p0, ix), _mm256_mullo_epi16(p1, fx));
}

// (top, bottom) pairs of one 128-bit half against (128 - fy, fy) per pixel, in 32 bits.
PROCAM_AVX2_INLINE __m256i finishY(__m256i tb, __m256i w) {
  return _mm256_srli_epi32(_mm256_add_epi32(_mm256_madd_epi16(tb, w), _mm256_set1_epi32(kRound)),
                           kShift);
}

// Eight pixels from their footprint corners (one RGBA8 texel per 32-bit lane) and their
// sub-pixel positions fx, fy (0..128 per 32-bit lane); zero where `valid` is clear.
PROCAM_AVX2_INLINE __m256i blend8(__m256i p00, __m256i p01, __m256i p10, __m256i p11, __m256i fx,
                                  __m256i fy, __m256i valid) {
  const __m256i low_bytes = _mm256_set1_epi32(0x00ff00ff);
  const __m256i one = _mm256_set1_epi32(kSubpixelOne);
  // Weights in both 16-bit halves of a pixel's lane: R,B and G,A are 16-bit lane pairs.
  const __m256i fx2 = _mm256_or_si256(fx, _mm256_slli_epi32(fx, 16));
  const __m256i ix = _mm256_sub_epi32(one, fx);
  const __m256i ix2 = _mm256_or_si256(ix, _mm256_slli_epi32(ix, 16));
  const __m256i wy = _mm256_or_si256(_mm256_sub_epi32(one, fy), _mm256_slli_epi32(fy, 16));
  const __m256i t_rb =
      blendX(ix2, fx2, _mm256_and_si256(p00, low_bytes), _mm256_and_si256(p01, low_bytes));
  const __m256i t_ga = blendX(ix2, fx2, _mm256_srli_epi16(p00, 8), _mm256_srli_epi16(p01, 8));
  const __m256i b_rb =
      blendX(ix2, fx2, _mm256_and_si256(p10, low_bytes), _mm256_and_si256(p11, low_bytes));
  const __m256i b_ga = blendX(ix2, fx2, _mm256_srli_epi16(p10, 8), _mm256_srli_epi16(p11, 8));
  const __m256i wy_lo = _mm256_unpacklo_epi32(wy, wy), wy_hi = _mm256_unpackhi_epi32(wy, wy);
  // 32-bit lanes R | G << 8 and B | A << 8, two per pixel; pixel order after the pack.
  const __m256i lo =
      _mm256_or_si256(finishY(_mm256_unpacklo_epi16(t_rb, b_rb), wy_lo),
                      _mm256_slli_epi32(finishY(_mm256_unpacklo_epi16(t_ga, b_ga), wy_lo), 8));
  const __m256i hi =
      _mm256_or_si256(finishY(_mm256_unpackhi_epi16(t_rb, b_rb), wy_hi),
                      _mm256_slli_epi32(finishY(_mm256_unpackhi_epi16(t_ga, b_ga), wy_hi), 8));
  return _mm256_and_si256(_mm256_packus_epi32(lo, hi), valid);
}

// How far ahead along an output row the kernels prefetch the source footprint. The
// footprints of a warped row run diagonally through the source, a pattern the hardware
// prefetchers miss: without this the kernels wait on L3 and DRAM (render bench: -35 to -45 %
// time, warm and cold, at 32 to 256 pixels ahead).
inline constexpr int kPrefetchPixels = 64;

// Both source rows of a footprint at byte offset `off` into the L1 cache.
inline void prefetchFootprint(const uint8_t* src, size_t src_step, int32_t off) {
  _mm_prefetch(reinterpret_cast<const char*>(src + off), _MM_HINT_T0);
  _mm_prefetch(reinterpret_cast<const char*>(src + off + src_step), _MM_HINT_T0);
}

// Blends eight pixels whose footprints start at byte offsets `off` (>= 0 everywhere;
// outside pixels point at any texel and are cleared by `valid`) into out[0..32). One gather
// per footprint corner (measured on Zen 4 against 8-byte pair loads: equal or faster).
PROCAM_AVX2_INLINE void blendStore8(const uint8_t* src, size_t src_step, __m256i off, __m256i fx,
                                    __m256i fy, __m256i valid, uint8_t* out) {
  const auto* top = reinterpret_cast<const int*>(src);
  const auto* bottom = reinterpret_cast<const int*>(src + src_step);
  const __m256i right = _mm256_add_epi32(off, _mm256_set1_epi32(4));
  const __m256i p00 = _mm256_i32gather_epi32(top, off, 1);
  const __m256i p01 = _mm256_i32gather_epi32(top, right, 1);
  const __m256i p10 = _mm256_i32gather_epi32(bottom, off, 1);
  const __m256i p11 = _mm256_i32gather_epi32(bottom, right, 1);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), blend8(p00, p01, p10, p11, fx, fy, valid));
}

}  // namespace procam::render::avx2
#endif
