#include "render/remap_rgba.hpp"

#include <algorithm>
#include <cstring>

#include "render/bilinear_avx2.hpp"

#if defined(__x86_64__)
#include <emmintrin.h>
#endif

namespace procam::render {
namespace {

constexpr int kShift = 2 * kSubpixelBits;
constexpr int kRound = 1 << (kShift - 1);

// Weights of the 2x2 footprint; they sum to 128 * 128.
struct Weights {
  int w00, w01, w10, w11;
};

inline Weights weights(uint8_t fx, uint8_t fy) {
  const int ix = kSubpixelOne - fx, iy = kSubpixelOne - fy;
  return {ix * iy, fx * iy, ix * fy, fx * fy};
}

inline uint32_t loadPixel(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

void rowScalar(const uint8_t* src, size_t src_step, const PackedRow& row, int width, uint8_t* out) {
  for (int x = 0; x < width; ++x) {
    const int32_t off = row.offset[x];
    uint8_t* o = out + 4 * x;
    if (off < 0) {
      std::memset(o, 0, 4);
      continue;
    }
    const uint8_t* p0 = src + off;
    const uint8_t* p1 = p0 + src_step;
    const Weights w = weights(row.fx[x], row.fy[x]);
    for (int c = 0; c < 4; ++c) {
      const int v = p0[c] * w.w00 + p0[4 + c] * w.w01 + p1[c] * w.w10 + p1[4 + c] * w.w11;
      o[c] = static_cast<uint8_t>((v + kRound) >> kShift);
    }
  }
}

#if defined(__x86_64__)
void rowSse2(const uint8_t* src, size_t src_step, const PackedRow& row, int width, uint8_t* out) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i round = _mm_set1_epi32(kRound);
  for (int x = 0; x < width; ++x) {
    const int32_t off = row.offset[x];
    if (off < 0) {
      std::memset(out + 4 * x, 0, 4);
      continue;
    }
    const uint8_t* p0 = src + off;
    const uint8_t* p1 = p0 + src_step;
    // Interleave the two texels of a row channel by channel (r0 r1 g0 g1 ...), widen to
    // 16 bits and let madd form p0 * w0 + p1 * w1 per channel in 32 bits.
    const __m128i top =
        _mm_unpacklo_epi8(_mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(loadPixel(p0))),
                                            _mm_cvtsi32_si128(static_cast<int>(loadPixel(p0 + 4)))),
                          zero);
    const __m128i bottom =
        _mm_unpacklo_epi8(_mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(loadPixel(p1))),
                                            _mm_cvtsi32_si128(static_cast<int>(loadPixel(p1 + 4)))),
                          zero);
    const Weights w = weights(row.fx[x], row.fy[x]);
    const __m128i wt = _mm_set1_epi32(w.w00 | (w.w01 << 16));
    const __m128i wb = _mm_set1_epi32(w.w10 | (w.w11 << 16));
    __m128i sum = _mm_add_epi32(_mm_madd_epi16(top, wt), _mm_madd_epi16(bottom, wb));
    sum = _mm_srli_epi32(_mm_add_epi32(sum, round), kShift);
    sum = _mm_packs_epi32(sum, sum);
    sum = _mm_packus_epi16(sum, sum);
    const uint32_t v = static_cast<uint32_t>(_mm_cvtsi128_si32(sum));
    std::memcpy(out + 4 * x, &v, 4);
  }
}

// Eight pixels per step (bilinear_avx2.hpp), the last width % 8 by rowScalar.
PROCAM_AVX2 void rowAvx2(const uint8_t* src, size_t src_step, const PackedRow& row, int width,
                         uint8_t* out) {
  const __m256i minus_one = _mm256_set1_epi32(-1);
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    const int32_t ahead = row.offset[std::min(x + avx2::kPrefetchPixels, width - 1)];
    if (ahead >= 0) avx2::prefetchFootprint(src, src_step, ahead);
    const __m256i off = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row.offset + x));
    const __m256i valid = _mm256_cmpgt_epi32(off, minus_one);
    if (_mm256_testz_si256(valid, valid)) {  // e.g. the black margin around a keystoned image
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 4 * x), _mm256_setzero_si256());
      continue;
    }
    int64_t fx8, fy8;
    std::memcpy(&fx8, row.fx + x, 8);
    std::memcpy(&fy8, row.fy + x, 8);
    avx2::blendStore8(src, src_step, _mm256_and_si256(off, valid),
                      _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(fx8)),
                      _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(fy8)), valid, out + 4 * x);
  }
  if (x < width) {
    rowScalar(src, src_step, {row.offset + x, row.fx + x, row.fy + x}, width - x, out + 4 * x);
  }
}
#endif

}  // namespace

RemapRowFn remapRowKernel(RemapKernel kernel) {
#if defined(__x86_64__)
  if (kernel == RemapKernel::kBest && __builtin_cpu_supports("avx2")) return rowAvx2;
  if (kernel != RemapKernel::kScalar) return rowSse2;
#else
  (void)kernel;
#endif
  return rowScalar;
}

Result<void> remapRgba(const cv::Mat& src, const PackedMap& map, cv::Mat& dst, RemapKernel kernel) {
  if (src.type() != CV_8UC4 || src.size() != map.source_size ||
      static_cast<int>(src.step) != map.source_step) {
    return fail(ErrorCode::kInvalidInput,
                "remapRgba: source is not CV_8UC4 of the size and row step the map was packed for");
  }
  if (map.offset.size() != static_cast<size_t>(map.output_size.area())) {
    return fail(ErrorCode::kInvalidInput, "remapRgba: malformed packed map");
  }
  dst.create(map.output_size, CV_8UC4);
  const int width = map.output_size.width;
  const RemapRowFn row = remapRowKernel(kernel);
  // Stripes of rows; OpenCV's pool uses every core.
  cv::parallel_for_(
      cv::Range(0, map.output_size.height),
      [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
          const size_t k = static_cast<size_t>(y) * width;
          row(src.data, src.step, {&map.offset[k], &map.fx[k], &map.fy[k]}, width,
              dst.ptr<uint8_t>(y));
        }
      },
      16);
  return {};
}

}  // namespace procam::render
