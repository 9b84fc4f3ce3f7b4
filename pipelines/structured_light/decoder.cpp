#include "structured_light/decoder.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <type_traits>
#include <vector>

#include "structured_light/gray_code.hpp"

namespace procam::sl {
namespace {

struct AxisFrames {
  AxisCode code;
  std::vector<int> gray, inverse, phase;  // frame indices
};

AxisFrames axisFrames(const PatternSet& set, Axis axis) {
  AxisFrames a;
  a.code = set.code(axis);
  for (int b = 0; b < a.code.bits; ++b) {
    a.gray.push_back(findFrame(set, FrameKind::kGray, axis, b));
    a.inverse.push_back(findFrame(set, FrameKind::kGrayInverse, axis, b));
  }
  for (int n = 0; n < set.phaseSteps(); ++n)
    a.phase.push_back(findFrame(set, FrameKind::kPhase, axis, n));
  return a;
}

// Per-row scratch, allocated once per stripe of rows (never per pixel). The per-bit
// loops run on integer lanes of one width W (int16 for 8-bit captures, int32 for
// 16-bit ones) so that they vectorise: min/max are single SIMD instructions there.
template <class W>
struct Scratch {
  using U = std::make_unsigned_t<W>;
  std::vector<U> code, weak, bad;
  std::vector<W> min1, min2, firm, hi, lo;
  std::vector<float> inv_contrast, inv_linear_contrast, sin_sum, cos_sum;
  explicit Scratch(int n)
      : code(n),
        weak(n),
        bad(n),
        min1(n),
        min2(n),
        firm(n),
        hi(n),
        lo(n),
        inv_contrast(n),
        inv_linear_contrast(n),
        sin_sum(n),
        cos_sum(n) {}
};

// One Gray bit of a row: the code gains the bit, plus the two smallest |pattern -
// inverse| (normalised at the end), the weak bits (a mask like the code) and the range check
// against [black, white]. Restrict-qualified parameters let the compiler vectorise.
template <class T, class W, class U>
void accumulateBit(const T* __restrict p, const T* __restrict q, U* __restrict code,
                   U* __restrict weak, U* __restrict bad, W* __restrict min1, W* __restrict min2,
                   const W* __restrict firm, const W* __restrict hi, const W* __restrict lo,
                   int width) {
  for (int x = 0; x < width; ++x) {
    const W pv = static_cast<W>(p[x]), qv = static_cast<W>(q[x]);
    const W d = static_cast<W>(pv - qv);
    const W ad = std::max(d, static_cast<W>(-d));
    code[x] = static_cast<U>((code[x] << 1) | static_cast<U>(d > 0));
    weak[x] = static_cast<U>((weak[x] << 1) | static_cast<U>(ad < firm[x]));
    min2[x] = std::min(min2[x], std::max(min1[x], ad));
    min1[x] = std::min(min1[x], ad);
    bad[x] = static_cast<U>(bad[x] | static_cast<U>(std::max(pv, qv) > hi[x]) |
                            static_cast<U>(std::min(pv, qv) < lo[x]));
  }
}

// std::lround's rounding (halves away from zero) for the small magnitudes of pixel
// codes (|v| < 2^23), without its library call: the conversion truncates towards zero.
inline int roundHalfAway(float v) {
  return static_cast<int>(v + std::copysign(0.5f, v));
}

template <class T>
class RowDecoder {
  using W = std::conditional_t<sizeof(T) == 1, std::int16_t, std::int32_t>;
  using U = std::make_unsigned_t<W>;
  using Rows = Scratch<W>;

 public:
  // `linear`: code -> linear signal for the phase frames (empty: the identity).
  RowDecoder(const PatternSet& set, const std::vector<cv::Mat>& frames,
             const DecodeOptions& options, double full_scale, const std::vector<float>& linear,
             Decoded& out)
      : set_(set),
        frames_(frames),
        o_(options),
        full_(static_cast<float>(full_scale)),
        linear_(linear),
        out_(out),
        white_(findFrame(set, FrameKind::kWhite, Axis::kColumns, 0)),
        black_(findFrame(set, FrameKind::kBlack, Axis::kColumns, 0)),
        axes_{axisFrames(set, Axis::kColumns), axisFrames(set, Axis::kRows)} {
    const int n = set.phaseSteps();
    for (int i = 0; i < n; ++i) {
      const double delta = 2 * std::numbers::pi * i / n;
      sin_.push_back(static_cast<float>(std::sin(delta)));
      cos_.push_back(static_cast<float>(std::cos(delta)));
    }
  }

  void operator()(const cv::Range& rows) const {
    const int width = frames_[0].cols;
    Rows s(width);
    std::vector<float> confidence(width);
    for (int y = rows.start; y < rows.end; ++y) {
      const T* w = frames_[white_].ptr<T>(y);
      const T* b = frames_[black_].ptr<T>(y);
      std::uint8_t* flags = out_.flags.ptr<std::uint8_t>(y);
      const float min_contrast = static_cast<float>(o_.min_contrast) * full_;
      const float saturated = static_cast<float>(o_.saturation) * full_;
      const float tol_abs = 0.02f * full_;
      const bool phase = set_.phaseSteps() > 0;
      for (int x = 0; x < width; ++x) {
        const float contrast = static_cast<float>(w[x]) - static_cast<float>(b[x]);
        std::uint8_t f = 0;
        if (contrast < min_contrast) f |= kShadow;
        if (b[x] >= saturated || (phase && w[x] >= saturated)) f |= kSaturated;
        flags[x] = f;
        s.inv_contrast[x] = contrast > 0 ? 1.0f / contrast : 0.0f;
        if (phase) {
          const float linear_contrast = linear_.empty() ? contrast : linear_[w[x]] - linear_[b[x]];
          s.inv_linear_contrast[x] = linear_contrast > 0 ? 1.0f / linear_contrast : 0.0f;
        }
        const float tol =
            static_cast<float>(o_.range_tolerance) * std::max(contrast, 0.0f) + tol_abs;
        s.hi[x] = static_cast<W>(roundHalfAway(static_cast<float>(w[x]) + tol));
        s.lo[x] = static_cast<W>(roundHalfAway(static_cast<float>(b[x]) - tol));
        s.firm[x] = static_cast<W>(
            roundHalfAway(static_cast<float>(o_.bit_contrast) * std::max(contrast, 0.0f)));
        confidence[x] = 1.0f;
      }
      decodeAxis(axes_[0], y, s, flags, confidence.data(), out_.u.ptr<float>(y));
      decodeAxis(axes_[1], y, s, flags, confidence.data(), out_.v.ptr<float>(y));
      float* u = out_.u.ptr<float>(y);
      float* v = out_.v.ptr<float>(y);
      float* c = out_.confidence.ptr<float>(y);
      for (int x = 0; x < width; ++x) {
        const bool ok = flags[x] == 0;
        u[x] = ok ? u[x] : -1.0f;
        v[x] = ok ? v[x] : -1.0f;
        c[x] = ok ? std::clamp(confidence[x], 0.0f, 1.0f) : 0.0f;
      }
    }
  }

 private:
  void decodeAxis(const AxisFrames& a, int y, Rows& s, std::uint8_t* flags, float* confidence,
                  float* out) const {
    const int width = frames_[0].cols;
    constexpr W kMax = std::numeric_limits<W>::max();
    std::fill(s.code.begin(), s.code.end(), U{0});
    std::fill(s.weak.begin(), s.weak.end(), U{0});
    std::fill(s.bad.begin(), s.bad.end(), U{0});
    std::fill(s.min1.begin(), s.min1.end(), kMax);
    std::fill(s.min2.begin(), s.min2.end(), kMax);
    U* code_p = s.code.data();
    U* weak_p = s.weak.data();
    U* bad_p = s.bad.data();
    W* min1_p = s.min1.data();
    W* min2_p = s.min2.data();
    const W* firm_p = s.firm.data();
    const W* hi_p = s.hi.data();
    const W* lo_p = s.lo.data();
    for (std::size_t bit = 0; bit < a.gray.size(); ++bit) {
      const T* p = frames_[a.gray[bit]].ptr<T>(y);
      const T* q = frames_[a.inverse[bit]].ptr<T>(y);
      accumulateBit(p, q, code_p, weak_p, bad_p, min1_p, min2_p, firm_p, hi_p, lo_p, width);
    }
    const AxisCode& code = a.code;
    const bool phase = !a.phase.empty();
    if (phase) accumulatePhase(a, y, s);
    const double period = code.period;
    const double two_pi = 2 * std::numbers::pi;
    const float amplitude_scale = phase ? 4.0f / static_cast<float>(a.phase.size()) : 0.0f;
    // With phase the Gray code only unwraps, and a block centre more than a cell
    // off would unwrap to the wrong period.
    const int max_blurred = phase ? 0 : o_.max_blurred_bits;
    for (int x = 0; x < width; ++x) {
      if (flags[x] != 0) continue;
      std::uint8_t f = 0;
      // Weak bits: the one flipping at a stripe edge, and, where a camera pixel spans
      // more than the finest stripes, the finest bits blurred out. A run of weak
      // bits ending at the finest (up to max_blurred_bits) leaves the code known to
      // blocks of 2^blurred cells: the pixel decodes to its block's centre.
      if (s.bad[x]) f |= kInconsistent;
      const auto weak = static_cast<std::uint32_t>(s.weak[x]);
      int blurred = 0;
      if (std::popcount(weak) > o_.max_weak_bits) {
        blurred = std::countr_one(weak);
        if (blurred > max_blurred || blurred >= code.bits ||
            std::popcount(weak >> blurred) > o_.max_weak_bits)
          f |= kLowContrast;
      }
      const std::uint32_t cell = fromGray(static_cast<std::uint32_t>(s.code[x]) >> blurred);
      const int block = code.cell << blurred;
      if (cell >= static_cast<std::uint32_t>((code.extent + block - 1) / block)) f |= kInconsistent;
      float conf = code.bits >= 2   ? static_cast<float>(s.min2[x]) * s.inv_contrast[x]
                   : code.bits == 1 ? static_cast<float>(s.min1[x]) * s.inv_contrast[x]
                                    : 1.0f;
      const int first = static_cast<int>(cell) * block;
      const int width_of_cell = std::min(block, code.extent - first);
      double position = first + (width_of_cell - 1) * 0.5;
      if (phase && f == 0) {
        // N-step phase: sum I_n cos(theta - delta_n) sin/cos(delta_n) = N/2 sin/cos(theta).
        const float sv = s.sin_sum[x], cv = s.cos_sum[x];
        const float modulation =
            amplitude_scale * std::sqrt(sv * sv + cv * cv) * s.inv_linear_contrast[x];
        if (modulation < o_.min_modulation) f |= kLowContrast;
        double wrapped = std::atan2(static_cast<double>(sv), static_cast<double>(cv)) / two_pi;
        if (wrapped < 0) wrapped += 1.0;
        wrapped *= period;
        const double unwrapped = wrapped + period * std::round((position - wrapped) / period);
        if (std::abs(unwrapped - position) > 1.75 * code.cell) f |= kInconsistent;
        position = unwrapped;
        conf = std::min(conf, modulation);
      }
      if (position < -0.5 || position > code.extent - 0.5) f |= kInconsistent;
      flags[x] |= f;
      out[x] = static_cast<float>(position);
      confidence[x] = std::min(confidence[x], conf);
    }
  }

  void accumulatePhase(const AxisFrames& a, int y, Rows& s) const {
    const int width = frames_[0].cols;
    std::fill(s.sin_sum.begin(), s.sin_sum.end(), 0.0f);
    std::fill(s.cos_sum.begin(), s.cos_sum.end(), 0.0f);
    for (std::size_t n = 0; n < a.phase.size(); ++n) {
      const T* p = frames_[a.phase[n]].ptr<T>(y);
      const float sn = sin_[n], cn = cos_[n];
      if (linear_.empty()) {
        for (int x = 0; x < width; ++x) {
          const float v = static_cast<float>(p[x]);
          s.sin_sum[x] += v * sn;
          s.cos_sum[x] += v * cn;
        }
      } else {
        const float* lin = linear_.data();
        for (int x = 0; x < width; ++x) {
          const float v = lin[p[x]];
          s.sin_sum[x] += v * sn;
          s.cos_sum[x] += v * cn;
        }
      }
    }
  }

  const PatternSet& set_;
  const std::vector<cv::Mat>& frames_;
  const DecodeOptions& o_;
  float full_;
  const std::vector<float>& linear_;
  Decoded& out_;
  int white_, black_;
  AxisFrames axes_[2];
  std::vector<float> sin_, cos_;
};

// The camera's response exponent g from the phase frames of one axis: with a
// linear signal L = c^g (c the code over full scale), the N shifted sinusoids of a
// pixel average to (L_white + L_black) / 2 whatever their phase, and the normalised
// excess of that average decreases monotonically in g. Bisection on its median
// over a sparse grid of well-lit, modulated pixels; 1 when it cannot be told.
template <class T>
double estimateResponseGamma(const std::vector<cv::Mat>& frames, int white, int black,
                             const std::vector<int>& phase, double full, const DecodeOptions& o) {
  const int n = static_cast<int>(phase.size());
  const cv::Size size = frames[0].size();
  const int stride = std::max(1, static_cast<int>(std::sqrt(size.area() / 3000.0)));
  std::vector<float> logs;  // per pixel: log c_white, log c_black, log c_n ...
  for (int y = stride / 2; y < size.height; y += stride) {
    const T* w = frames[white].ptr<T>(y);
    const T* b = frames[black].ptr<T>(y);
    for (int x = stride / 2; x < size.width; x += stride) {
      if (w[x] - static_cast<double>(b[x]) < 0.15 * full || w[x] >= o.saturation * full) continue;
      double lo = w[x], hi = b[x];
      for (int i : phase) {
        const double v = frames[i].ptr<T>(y)[x];
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (hi - lo < 0.3 * (w[x] - static_cast<double>(b[x]))) continue;  // blurred out
      auto lg = [full](double code) {
        return static_cast<float>(std::log(std::max(code, 0.5) / full));
      };
      logs.push_back(lg(w[x]));
      logs.push_back(lg(b[x]));
      for (int i : phase) logs.push_back(lg(frames[i].ptr<T>(y)[x]));
    }
  }
  const std::size_t per = static_cast<std::size_t>(n) + 2, pixels = logs.size() / per;
  if (pixels < 50) return 1.0;
  std::vector<double> excess(pixels);
  auto medianExcess = [&](double g) {
    for (std::size_t p = 0; p < pixels; ++p) {
      const float* l = &logs[p * per];
      const double lw = std::exp(g * l[0]), lb = std::exp(g * l[1]);
      double mean = 0;
      for (int i = 0; i < n; ++i) mean += std::exp(g * l[2 + i]);
      excess[p] = (mean / n - 0.5 * (lw + lb)) / std::max(lw - lb, 1e-12);
    }
    std::nth_element(excess.begin(), excess.begin() + pixels / 2, excess.end());
    return excess[pixels / 2];
  };
  double lo = 0.2, hi = 5.0;
  if (medianExcess(lo) < 0 || medianExcess(hi) > 0) return 1.0;
  for (int it = 0; it < 24; ++it) {
    const double mid = 0.5 * (lo + hi);
    (medianExcess(mid) > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Marks decoded pixels with fewer than `needed` consistent direct neighbours (two
// per image axis along which the pixel lies on a straight line in projector space), and
// (partial > 0) partly lit ones whose contrast is below `partial` of their
// brightest neighbour's less `margin`; all read before any is dropped, so the
// result does not depend on order.
template <class T>
void dropUnreliable(Decoded& d, const cv::Mat& white, const cv::Mat& black, float tol_u,
                    float tol_v, int needed, float partial, float margin) {
  const int w = d.u.cols, h = d.u.rows;
  cv::Mat drop(d.u.size(), CV_8U, cv::Scalar(0));
  cv::parallel_for_(
      cv::Range(0, h),
      [&](const cv::Range& rows) {
        // The stripe's rows and two above and below, each loaded once, padded by two
        // pixels each side: out-of-image neighbours are undecoded with zero contrast, so
        // the inner loop has no bounds tests.
        const int pw = w + 4, first = rows.start - 2, count = rows.end - rows.start + 4;
        std::vector<float> contrast(static_cast<std::size_t>(count) * pw), u(contrast.size()),
            v(contrast.size());
        std::vector<std::uint8_t> ok(contrast.size());
        for (int slot = 0; slot < count; ++slot) {
          const int y = first + slot;
          float* c = contrast.data() + static_cast<std::size_t>(slot) * pw;
          float* uu = u.data() + static_cast<std::size_t>(slot) * pw;
          float* vv = v.data() + static_cast<std::size_t>(slot) * pw;
          std::uint8_t* o = ok.data() + static_cast<std::size_t>(slot) * pw;
          std::fill(c, c + pw, 0.0f);
          std::fill(o, o + pw, std::uint8_t{0});
          if (y < 0 || y >= h) continue;
          const T* wh = white.ptr<T>(y);
          const T* bl = black.ptr<T>(y);
          const std::uint8_t* f = d.flags.ptr<std::uint8_t>(y);
          const float* su = d.u.ptr<float>(y);
          const float* sv = d.v.ptr<float>(y);
          for (int x = 0; x < w; ++x) {
            c[x + 2] = static_cast<float>(wh[x]) - static_cast<float>(bl[x]);
            o[x + 2] = f[x] == 0;
            uu[x + 2] = su[x];
            vv[x + 2] = sv[x];
          }
        }
        for (int y = rows.start; y < rows.end; ++y) {
          std::uint8_t* out = drop.ptr<std::uint8_t>(y);
          const std::size_t at = static_cast<std::size_t>(y - first) * pw + 2;  // row y, x = 0
          const float* c = contrast.data() + at;
          const float* uc = u.data() + at;
          const float* vc = v.data() + at;
          const std::uint8_t* oc = ok.data() + at;
          // Three decoded pixels in a line at x + a*off, x + (a+1)*off, x + (a+2)*off whose
          // second difference stays within the tolerance.
          auto straight = [&](int i, int off, int a) {
            const int p = i + a * off, q = p + off, r = q + off;
            return oc[p] && oc[q] && oc[r] && std::abs(uc[p] + uc[r] - 2 * uc[q]) <= 2 * tol_u &&
                   std::abs(vc[p] + vc[r] - 2 * vc[q]) <= 2 * tol_v;
          };
          for (int x = 0; x < w; ++x) {
            if (!oc[x]) continue;
            std::uint8_t flag = 0;
            if (needed > 0) {
              // Second differences along each image axis: the first-order change between
              // neighbours (the projector pixels one camera pixel spans, several when the
              // camera is coarser than the projector) cancels, so the tolerance holds at
              // any footprint while a slipped code (a Gray cell or a phase period) shows
              // twice over (once when the pixel ends the line, at the edge of the
              // decoded area). Each agreeing axis counts as two neighbours.
              int n = 0;
              for (const int off : {1, pw}) {
                const bool centred = oc[x - off] && oc[x + off];
                n += (centred ? straight(x, off, -1) : straight(x, off, 0) || straight(x, off, -2))
                         ? 2
                         : 0;
              }
              if (n < needed) flag |= kInconsistent;
            }
            if (partial > 0) {
              const float brightest =
                  std::max(std::max(c[x - 1], c[x + 1]), std::max(c[x - pw], c[x + pw]));
              if (c[x] < partial * brightest - margin) flag |= kShadow;
            }
            out[x] = flag;
          }
        }
      },
      // Stripes of ~32 rows: each reloads only its four border rows.
      std::max(1, h / 32));
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* dr = drop.ptr<std::uint8_t>(y);
    std::uint8_t* f = d.flags.ptr<std::uint8_t>(y);
    float* u = d.u.ptr<float>(y);
    float* v = d.v.ptr<float>(y);
    float* c = d.confidence.ptr<float>(y);
    for (int x = 0; x < w; ++x)
      if (dr[x]) f[x] |= dr[x], u[x] = v[x] = -1.0f, c[x] = 0.0f;
  }
}

}  // namespace

Result<Decoded> decode(const PatternSet& set, std::span<const cv::Mat> captures,
                       const DecodeOptions& options) {
  if (captures.size() != set.frames.size())
    return fail(ErrorCode::kInvalidInput, "expected " + std::to_string(set.frames.size()) +
                                              " captures, got " + std::to_string(captures.size()));
  if (captures.empty() || captures[0].empty())
    return fail(ErrorCode::kInvalidInput, "empty capture");
  const cv::Size size = captures[0].size();
  std::vector<cv::Mat> frames(captures.size());
  int depth = -1;
  for (std::size_t i = 0; i < captures.size(); ++i) {
    const cv::Mat& c = captures[i];
    if (c.size() != size)
      return fail(ErrorCode::kInvalidInput,
                  "capture " + set.frames[i].name + " is " + std::to_string(c.cols) + "x" +
                      std::to_string(c.rows) + ", expected " + std::to_string(size.width) + "x" +
                      std::to_string(size.height));
    if (c.depth() != CV_8U && c.depth() != CV_16U)
      return fail(ErrorCode::kInvalidInput, "captures must be 8- or 16-bit");
    if (depth >= 0 && c.depth() != depth)
      return fail(ErrorCode::kInvalidInput, "captures mix 8- and 16-bit images");
    depth = c.depth();
    if (c.channels() == 1) {
      frames[i] = c;
    } else if (c.channels() == 3 || c.channels() == 4) {
      cv::cvtColor(c, frames[i], c.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
    } else {
      return fail(ErrorCode::kInvalidInput, "captures must have 1, 3 or 4 channels");
    }
  }
  double full = options.full_scale;
  if (!(full > 0)) {
    full = 255.0;
    if (depth == CV_16U) {
      double max_white = 0;
      cv::minMaxLoc(
          frames[static_cast<std::size_t>(findFrame(set, FrameKind::kWhite, Axis::kColumns, 0))],
          nullptr, &max_white);
      full = 65535.0;
      for (int bits : {10, 12, 14})
        if (max_white <= (1 << bits) - 1) {
          full = (1 << bits) - 1;
          break;
        }
    }
  }
  // Phase frames through the inverse camera response (identity when ~linear).
  std::vector<float> linear;
  double gamma = 1.0;
  if (set.phaseSteps() > 0) {
    gamma = options.response_gamma;
    if (!(gamma > 0)) {
      const int white = findFrame(set, FrameKind::kWhite, Axis::kColumns, 0);
      const int black = findFrame(set, FrameKind::kBlack, Axis::kColumns, 0);
      std::vector<int> phase;
      for (int i = 0; i < set.phaseSteps(); ++i)
        phase.push_back(findFrame(set, FrameKind::kPhase, Axis::kColumns, i));
      gamma =
          depth == CV_8U
              ? estimateResponseGamma<std::uint8_t>(frames, white, black, phase, full, options)
              : estimateResponseGamma<std::uint16_t>(frames, white, black, phase, full, options);
    }
    if (std::abs(gamma - 1.0) > 0.03) {
      linear.resize(depth == CV_8U ? 256 : 65536);
      for (std::size_t c = 0; c < linear.size(); ++c)
        linear[c] = static_cast<float>(full * std::pow(static_cast<double>(c) / full, gamma));
    } else {
      gamma = 1.0;
    }
  }
  Decoded out;
  out.response_gamma = gamma;
  out.u.create(size, CV_32F);
  out.v.create(size, CV_32F);
  out.confidence.create(size, CV_32F);
  out.flags.create(size, CV_8U);
  const int stripes = std::max(1, size.height / 8);
  if (depth == CV_8U) {
    cv::parallel_for_(cv::Range(0, size.height),
                      RowDecoder<std::uint8_t>(set, frames, options, full, linear, out), stripes);
  } else {
    cv::parallel_for_(cv::Range(0, size.height),
                      RowDecoder<std::uint16_t>(set, frames, options, full, linear, out), stripes);
  }
  if (options.min_consistent_neighbours > 0 || options.partial_contrast > 0) {
    const bool phase = set.phaseSteps() > 0;
    const double tol = options.neighbour_tolerance;
    const auto tol_u = static_cast<float>(tol + (phase ? 0 : set.columns.cell));
    const auto tol_v = static_cast<float>(tol + (phase ? 0 : set.rows.cell));
    const cv::Mat& white =
        frames[static_cast<std::size_t>(findFrame(set, FrameKind::kWhite, Axis::kColumns, 0))];
    const cv::Mat& black =
        frames[static_cast<std::size_t>(findFrame(set, FrameKind::kBlack, Axis::kColumns, 0))];
    const auto partial = static_cast<float>(std::max(0.0, options.partial_contrast));
    const auto margin = static_cast<float>(0.02 * full);
    if (depth == CV_8U)
      dropUnreliable<std::uint8_t>(out, white, black, tol_u, tol_v,
                                   options.min_consistent_neighbours, partial, margin);
    else
      dropUnreliable<std::uint16_t>(out, white, black, tol_u, tol_v,
                                    options.min_consistent_neighbours, partial, margin);
  }
  out.decoded = size.area() - cv::countNonZero(out.flags);
  return out;
}

}  // namespace procam::sl
