#include "render/warp_homography.hpp"

#include <algorithm>
#include <cmath>

#include "render/bilinear_avx2.hpp"

namespace procam::render {
namespace {

constexpr int kBlock = 8;  // pixels per double anchor (one AVX2 step)

// Source point of an output row, evaluated as every kernel does: the homogeneous point
// anchored in double at the block start, the lanes stepped in float.
struct RowGeometry {
  double ax, ay, aw;    // inverse * (0, y, 1)
  double dx, dy, dw;    // inverse.col(0): change per output pixel
  float fdx, fdy, fdw;  // the same in float
  float max_x, max_y;   // footprint bounds: width - 0.5, height - 0.5
  int last_x, last_y;   // width - 2, height - 2: top-left texel of the last footprint
  int step;             // source row step in bytes
};

RowGeometry rowGeometry(const HomographyWarp& w, int y, int step) {
  const Vec3 a = w.inverse * Vec3(0, y, 1);
  const Vec3 d = w.inverse.col(0);
  return {a.x(),
          a.y(),
          a.z(),
          d.x(),
          d.y(),
          d.z(),
          float(d.x()),
          float(d.y()),
          float(d.z()),
          float(w.source_size.width - 0.5),
          float(w.source_size.height - 0.5),
          w.source_size.width - 2,
          w.source_size.height - 2,
          step};
}

// One axis of packMap's quantisation: top-left texel and 1/128 px weight of the next one,
// the outer half pixel clamped to the edge texel.
inline void quantise(float s, int last, int32_t& i, uint8_t& f) {
  const int q = static_cast<int>(std::lrint(s * float(kSubpixelOne)));  // nearest, ties even
  int t = q >> kSubpixelBits, frac = q & (kSubpixelOne - 1);
  if (t < 0) {
    t = 0;
    frac = 0;
  } else if (t > last) {
    t = last;
    frac = kSubpixelOne;
  }
  i = t;
  f = static_cast<uint8_t>(frac);
}

// Packed entries of output pixels [x0, x0 + n) of a row, n <= kBlock, x0 % kBlock == 0.
void packBlock(const RowGeometry& g, int x0, int n, int32_t* off, uint8_t* fx, uint8_t* fy) {
  const float X = float(g.ax + x0 * g.dx), Y = float(g.ay + x0 * g.dy), W = float(g.aw + x0 * g.dw);
  for (int l = 0; l < n; ++l) {
    const float lane = float(l);
    const float px = X + lane * g.fdx, py = Y + lane * g.fdy, pw = W + lane * g.fdw;
    const float r = 1.0f / pw;  // one division for both axes, as the AVX2 kernel
    const float sx = px * r, sy = py * r;
    if (!(pw > 0.0f && sx >= -0.5f && sx < g.max_x && sy >= -0.5f && sy < g.max_y)) {
      off[l] = -1;
      fx[l] = fy[l] = 0;
      continue;
    }
    int32_t ix = 0, iy = 0;
    quantise(sx, g.last_x, ix, fx[l]);
    quantise(sy, g.last_y, iy, fy[l]);
    off[l] = iy * g.step + 4 * ix;
  }
}

void rowPacked(const uint8_t* src, const RowGeometry& g, int width, RemapRowFn kernel,
               uint8_t* out) {
  constexpr int kChunk = 32 * kBlock;
  int32_t off[kChunk];
  uint8_t fx[kChunk], fy[kChunk];
  for (int c = 0; c < width; c += kChunk) {
    const int n = std::min(kChunk, width - c);
    for (int b = 0; b < n; b += kBlock) {
      packBlock(g, c + b, std::min(kBlock, n - b), off + b, fx + b, fy + b);
    }
    kernel(src, size_t(g.step), {off, fx, fy}, n, out + 4 * c);
  }
}

#if defined(__x86_64__)
// One axis of quantise() for eight lanes (the footprint test is done by the caller).
PROCAM_AVX2_INLINE void quantise8(__m256 s, __m256i last, __m256i& i, __m256i& f) {
  const __m256i q = _mm256_cvtps_epi32(_mm256_mul_ps(s, _mm256_set1_ps(float(kSubpixelOne))));
  __m256i t = _mm256_srai_epi32(q, kSubpixelBits);
  __m256i frac = _mm256_and_si256(q, _mm256_set1_epi32(kSubpixelOne - 1));
  const __m256i below = _mm256_cmpgt_epi32(_mm256_setzero_si256(), t);
  t = _mm256_andnot_si256(below, t);
  frac = _mm256_andnot_si256(below, frac);
  const __m256i above = _mm256_cmpgt_epi32(t, last);
  i = _mm256_blendv_epi8(t, last, above);
  f = _mm256_blendv_epi8(frac, _mm256_set1_epi32(kSubpixelOne), above);
}

PROCAM_AVX2 void rowAvx2(const uint8_t* src, const RowGeometry& g, int width, uint8_t* out) {
  const __m256 lanes = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 sdx = _mm256_mul_ps(lanes, _mm256_set1_ps(g.fdx));
  const __m256 sdy = _mm256_mul_ps(lanes, _mm256_set1_ps(g.fdy));
  const __m256 sdw = _mm256_mul_ps(lanes, _mm256_set1_ps(g.fdw));
  const __m256 low = _mm256_set1_ps(-0.5f), max_x = _mm256_set1_ps(g.max_x),
               max_y = _mm256_set1_ps(g.max_y);
  const __m256i last_x = _mm256_set1_epi32(g.last_x), last_y = _mm256_set1_epi32(g.last_y);
  const __m256i step = _mm256_set1_epi32(g.step);
  int x = 0;
  for (; x + kBlock <= width; x += kBlock) {
    const __m256 px = _mm256_add_ps(_mm256_set1_ps(float(g.ax + x * g.dx)), sdx);
    const __m256 py = _mm256_add_ps(_mm256_set1_ps(float(g.ay + x * g.dy)), sdy);
    const __m256 pw = _mm256_add_ps(_mm256_set1_ps(float(g.aw + x * g.dw)), sdw);
    const __m256 r = _mm256_div_ps(_mm256_set1_ps(1.0f), pw);
    const __m256 sx = _mm256_mul_ps(px, r), sy = _mm256_mul_ps(py, r);
    __m256 in = _mm256_cmp_ps(pw, _mm256_setzero_ps(), _CMP_GT_OQ);
    in = _mm256_and_ps(in, _mm256_cmp_ps(sx, low, _CMP_GE_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(sx, max_x, _CMP_LT_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(sy, low, _CMP_GE_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(sy, max_y, _CMP_LT_OQ));
    if (_mm256_testz_ps(in, in)) {  // the black margin around a keystoned image
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 4 * x), _mm256_setzero_si256());
      continue;
    }
    const __m256i valid = _mm256_castps_si256(in);
    __m256i ix, iy, fx, fy;
    quantise8(sx, last_x, ix, fx);
    quantise8(sy, last_y, iy, fy);
    const __m256i off = _mm256_add_epi32(_mm256_mullo_epi32(iy, step), _mm256_slli_epi32(ix, 2));
    avx2::blendStore8(src, size_t(g.step), _mm256_and_si256(off, valid), fx, fy, valid,
                      out + 4 * x);
  }
  if (x < width) {
    int32_t off[kBlock];
    uint8_t fx[kBlock], fy[kBlock];
    packBlock(g, x, width - x, off, fx, fy);
    remapRowKernel(RemapKernel::kScalar)(src, size_t(g.step), {off, fx, fy}, width - x,
                                         out + 4 * x);
  }
}
#endif

}  // namespace

Result<HomographyWarp> makeHomographyWarp(const Mat3& H, cv::Size output_size,
                                          cv::Size source_size) {
  if (!H.allFinite() || output_size.width <= 0 || output_size.height <= 0) {
    return fail(ErrorCode::kInvalidInput, "makeHomographyWarp: non-finite H or empty output");
  }
  if (source_size.width < 2 || source_size.height < 2 ||
      4.0 * source_size.width * source_size.height > 2147483647.0) {
    return fail(ErrorCode::kInvalidInput, "makeHomographyWarp: source under 2x2 or over 2 GiB");
  }
  const double scale = H.row(0).norm() * H.row(1).norm() * H.row(2).norm();
  if (scale == 0 || std::abs(H.determinant()) < 1e-12 * scale) {
    return fail(ErrorCode::kDegenerate, "makeHomographyWarp: H is singular");
  }
  return HomographyWarp{H.inverse(), output_size, source_size};
}

Result<void> warpHomographyRgba(const cv::Mat& src, const HomographyWarp& warp, cv::Mat& dst,
                                RemapKernel kernel) {
  if (src.type() != CV_8UC4 || src.size() != warp.source_size ||
      static_cast<double>(src.step) * src.rows > 2147483647.0) {
    return fail(ErrorCode::kInvalidInput,
                "warpHomographyRgba: source is not CV_8UC4 of the warp's source size");
  }
  dst.create(warp.output_size, CV_8UC4);
  const int width = warp.output_size.width;
  const int step = static_cast<int>(src.step);
  const RemapRowFn row = remapRowKernel(kernel);
  [[maybe_unused]] bool avx2 = false;
#if defined(__x86_64__)
  avx2 = kernel == RemapKernel::kBest && __builtin_cpu_supports("avx2");
#endif
  cv::parallel_for_(
      cv::Range(0, warp.output_size.height),
      [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
          const RowGeometry g = rowGeometry(warp, y, step);
          uint8_t* out = dst.ptr<uint8_t>(y);
#if defined(__x86_64__)
          if (avx2) {
            rowAvx2(src.data, g, width, out);
            continue;
          }
#endif
          rowPacked(src.data, g, width, row, out);
        }
      },
      16);
  return {};
}

}  // namespace procam::render
