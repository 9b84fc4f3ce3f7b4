#pragma once
// Structured-light pattern sets ([Raskar02] §4.1.1 display-surface estimation, §4.1.4
// sampling density): Gray code for projector columns and rows, each bit followed by
// its inverse so the decoder thresholds every camera pixel against its own pair,
// all-white and all-black reference frames, and optionally N-step phase shifting
// unwrapped by the Gray code for sub-pixel correspondences.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace procam::sl {

enum class Mode { kGray, kGrayPhase };
enum class Axis { kColumns, kRows };
enum class FrameKind { kWhite, kBlack, kGray, kGrayInverse, kPhase };

struct PatternOptions {
  int width = 0;  // projector resolution
  int height = 0;
  Mode mode = Mode::kGray;
  // One code per `step` projector pixels: the low bits of the Gray code are dropped.
  int step = 1;
  int step_rows = 0;      // rows' step when it differs (0: same as step); coarse passes
  int phase_steps = 8;    // N >= 3 shifted sinusoids per axis (kGrayPhase)
  int phase_period = 32;  // sinusoid period in projector pixels; raised to 4*step
  // The sinusoid is pre-distorted by v^(1/gamma) so that a projector with this
  // response emits a sinusoidal radiance (1 = no pre-distortion). Gray frames are
  // binary and unaffected.
  double projector_gamma = 2.2;
};

// The code layout of one axis.
struct AxisCode {
  int extent = 0;  // projector pixels along the axis
  int cell = 1;    // projector pixels per Gray cell
  int cells = 0;   // ceil(extent / cell)
  int bits = 0;    // Gray bits (frames = 2 * bits, with inverses)
  int period = 0;  // phase period in projector pixels (0 without phase)
};

struct FrameInfo {
  FrameKind kind = FrameKind::kWhite;
  Axis axis = Axis::kColumns;
  int index = 0;     // Gray: bit, 0 = most significant; phase: shift n in [0, N)
  std::string name;  // file stem, e.g. "05_col_gray_02_inv"
};

struct PatternSet {
  PatternOptions options;
  AxisCode columns, rows;
  std::vector<FrameInfo> frames;  // white, black, column Gray pairs, row Gray pairs, phases

  const AxisCode& code(Axis axis) const { return axis == Axis::kColumns ? columns : rows; }
  int phaseSteps() const { return options.mode == Mode::kGrayPhase ? options.phase_steps : 0; }
};

const char* toString(Mode mode);
Result<Mode> parseMode(const std::string& text);  // "gray" | "gray+phase"

// kInvalidInput for sizes < 1 or > 65536, steps < 1, N < 3, period < 4 or gamma <= 0.
// In kGrayPhase the Gray cell is period/4 (period = max(phase_period, 4*step)), which
// keeps unwrapping unambiguous with a one-cell Gray error ([Raskar02] §4.1.4 trade-off).
Result<PatternSet> makePatternSet(const PatternOptions& options);

// The frame's image at projector resolution, CV_8UC1.
cv::Mat renderFrame(const PatternSet& set, std::size_t frame);

// Index of the frame with this kind/axis/index, or -1.
int findFrame(const PatternSet& set, FrameKind kind, Axis axis, int index);

}  // namespace procam::sl
