#include "render/remap_rgba.hpp"

#include <cstring>

#if defined(__SSE2__)
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

void rowScalar(const uint8_t* src, size_t src_step, const PackedMap& m, size_t k0, int width,
               uint8_t* out) {
  for (int x = 0; x < width; ++x) {
    const size_t k = k0 + x;
    const int32_t off = m.offset[k];
    uint8_t* o = out + 4 * x;
    if (off < 0) {
      std::memset(o, 0, 4);
      continue;
    }
    const uint8_t* p0 = src + off;
    const uint8_t* p1 = p0 + src_step;
    const Weights w = weights(m.fx[k], m.fy[k]);
    for (int c = 0; c < 4; ++c) {
      const int v = p0[c] * w.w00 + p0[4 + c] * w.w01 + p1[c] * w.w10 + p1[4 + c] * w.w11;
      o[c] = static_cast<uint8_t>((v + kRound) >> kShift);
    }
  }
}

#if defined(__SSE2__)
void rowSse2(const uint8_t* src, size_t src_step, const PackedMap& m, size_t k0, int width,
             uint8_t* out) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i round = _mm_set1_epi32(kRound);
  const int32_t* offsets = m.offset.data() + k0;
  const uint8_t* fxs = m.fx.data() + k0;
  const uint8_t* fys = m.fy.data() + k0;
  for (int x = 0; x < width; ++x) {
    const int32_t off = offsets[x];
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
    const Weights w = weights(fxs[x], fys[x]);
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
#endif

}  // namespace

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
  const uint8_t* s = src.data;
  const size_t step = src.step;
  [[maybe_unused]] bool simd = false;
#if defined(__SSE2__)
  simd = kernel == RemapKernel::kBest;
#else
  (void)kernel;
#endif
  // Stripes of rows; OpenCV's pool uses every core.
  cv::parallel_for_(
      cv::Range(0, map.output_size.height),
      [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
          const size_t k0 = static_cast<size_t>(y) * width;
          uint8_t* out = dst.ptr<uint8_t>(y);
#if defined(__SSE2__)
          if (simd) {
            rowSse2(s, step, map, k0, width, out);
            continue;
          }
#endif
          rowScalar(s, step, map, k0, width, out);
        }
      },
      16);
  return {};
}

}  // namespace procam::render
