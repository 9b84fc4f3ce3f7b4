#pragma once
// Structured-light decoder: camera pixel -> projector (u, v), sub-pixel, with a
// confidence and the reason why a pixel was not decoded. Every Gray bit is
// thresholded against its own inverse, so ambient light, the camera's response
// curve (gamma) and albedo cancel; mild defocus only blurs stripe edges, where the
// Gray code's one-bit-per-edge property bounds the error to one cell.
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>

#include "core/error.hpp"
#include "structured_light/pattern_set.hpp"

namespace procam::sl {

// Why a camera pixel has no correspondence (bits of Decoded::flags; 0 = decoded).
enum DecodeFlag : std::uint8_t {
  kShadow = 1,        // white - black below min_contrast: the projector does not reach it
  kLowContrast = 2,   // too many weak Gray bits, or phase modulation too low
  kSaturated = 4,     // black frame clipped, or (phase) white frame clipped
  kInconsistent = 8,  // a pattern frame outside [black, white], a code beyond the
                      // projector, or Gray and phase disagreeing
};

struct DecodeOptions {
  // Thresholds as fractions of the capture's full scale (255 or 65535 unless set).
  double min_contrast = 0.03;  // white - black
  double bit_contrast = 0.12;  // |pattern - inverse| / (white - black) for a firm bit
  int max_weak_bits = 1;       // per axis; the bit flipping at a stripe edge is weak
  // Finest Gray bits that may all be weak (blurred out where one camera pixel spans
  // more than their stripes), plus max_weak_bits above them: the pixel then decodes
  // to the centre of its block of 2^n cells. Gray-only sets (with phase the Gray
  // code only unwraps and needs every bit). 0: none.
  int max_blurred_bits = 4;
  double range_tolerance = 0.15;  // pattern may exceed [black, white] by this * (white - black)
  double saturation = 0.995;      // clipped at or above this fraction of full scale
  double min_modulation = 0.15;   // phase amplitude / ((white - black) / 2)
  // 0: 255 for 8-bit captures; for 16-bit ones the smallest 2^b - 1 (b = 10, 12, 14,
  // 16) covering the white frame, as 10- and 12-bit sensors store codes in 16 bits.
  double full_scale = 0;
  // The camera's response exponent g (code = full * linear^(1/g)) applied inverted
  // to the phase frames before the phase computation: a sinusoid seen through a
  // non-linear response gains harmonics, and with few shifts (N = 3) the second
  // aliases onto the fundamental. 0: estimated from the captures (the linearised
  // shifted frames of a pixel average to midway between its black and white);
  // 1: linear. Gray bits compare a frame with its inverse and need no linearising.
  double response_gamma = 0;
  // A decoded pixel needs this many of its 4 direct neighbours to agree with it
  // (kInconsistent otherwise): along an image axis, the pixel and its two neighbours
  // (or, at the edge of the decoded area, the next two inwards) must lie on a
  // straight line in projector space, second difference within 2 *
  // neighbour_tolerance projector pixels (plus one Gray cell without phase) on both
  // projector axes; such an axis counts as two neighbours. The second difference
  // cancels the projector pixels one camera pixel spans, however many, so the test
  // holds for cameras coarser than the projector, while an isolated noise-flipped
  // bit (a Gray cell or phase period off) still fails it. 0: off.
  int min_consistent_neighbours = 2;
  double neighbour_tolerance = 4.0;
  // Partly lit pixels (kShadow): white - black below this fraction of the largest
  // of its 4 direct neighbours', less 2% of full scale for noise. A camera pixel
  // straddling the edge of the lit area, a shadow or an occlusion mixes lit and
  // unlit light, and its code or phase is that of the lit part's centroid, not of
  // the pixel centre (up to a camera pixel off). Contrast varies smoothly across a
  // surface, so this drops only such edges and the dark side of sharp albedo edges.
  // 0: off.
  double partial_contrast = 0.85;
};

struct Decoded {
  cv::Mat u, v;               // CV_32F, projector pixel coordinates; -1 where undecoded
  cv::Mat confidence;         // CV_32F in [0, 1]; 0 where undecoded
  cv::Mat flags;              // CV_8U, DecodeFlag bits; 0 where decoded
  int decoded = 0;            // pixels with flags == 0
  double response_gamma = 1;  // the camera response exponent the phase frames were linearised with
};

// captures[i] shows set.frames[i]; all the same size, CV_8UC1/CV_16UC1 (3-channel
// captures are converted to grey first). kInvalidInput for a wrong frame count, sizes
// or depths.
Result<Decoded> decode(const PatternSet& set, std::span<const cv::Mat> captures,
                       const DecodeOptions& options = {});

}  // namespace procam::sl
