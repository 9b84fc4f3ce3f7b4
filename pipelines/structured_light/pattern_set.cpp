#include "structured_light/pattern_set.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "structured_light/gray_code.hpp"

namespace procam::sl {
namespace {

constexpr int kMaxExtent = 65536;

AxisCode makeAxis(int extent, int cell, int period) {
  AxisCode a;
  a.extent = extent;
  a.cell = std::min(cell, extent);
  a.cells = (extent + a.cell - 1) / a.cell;
  a.bits = bitsFor(static_cast<std::uint32_t>(a.cells));
  a.period = period;
  return a;
}

std::string frameName(std::size_t number, const char* what) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%02zu_%s", number, what);
  return buf;
}

void addAxisFrames(PatternSet& set, Axis axis) {
  const char* prefix = axis == Axis::kColumns ? "col" : "row";
  const AxisCode& code = set.code(axis);
  char what[48];
  for (int b = 0; b < code.bits; ++b) {
    std::snprintf(what, sizeof what, "%s_gray_%02d", prefix, b);
    set.frames.push_back({FrameKind::kGray, axis, b, frameName(set.frames.size(), what)});
    std::snprintf(what, sizeof what, "%s_gray_%02d_inv", prefix, b);
    set.frames.push_back({FrameKind::kGrayInverse, axis, b, frameName(set.frames.size(), what)});
  }
  for (int n = 0; n < set.phaseSteps(); ++n) {
    std::snprintf(what, sizeof what, "%s_phase_%02d", prefix, n);
    set.frames.push_back({FrameKind::kPhase, axis, n, frameName(set.frames.size(), what)});
  }
}

// Value of one projector column (or row) coordinate for a frame.
std::uint8_t codeValue(const PatternSet& set, const FrameInfo& f, int coordinate) {
  const AxisCode& code = set.code(f.axis);
  switch (f.kind) {
    case FrameKind::kWhite:
      return 255;
    case FrameKind::kBlack:
      return 0;
    case FrameKind::kGray:
    case FrameKind::kGrayInverse: {
      const auto cell = static_cast<std::uint32_t>(coordinate / code.cell);
      const int shift = code.bits - 1 - f.index;  // index 0 = most significant bit
      const bool on = ((toGray(cell) >> shift) & 1u) != 0;
      return (on != (f.kind == FrameKind::kGrayInverse)) ? 255 : 0;
    }
    case FrameKind::kPhase: {
      const double n = set.options.phase_steps;
      const double angle =
          2 * std::numbers::pi * (coordinate / static_cast<double>(code.period) - f.index / n);
      const double radiance = 0.5 + 0.5 * std::cos(angle);
      const double value = std::pow(radiance, 1.0 / set.options.projector_gamma);
      return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(value, 0.0, 1.0)));
    }
  }
  return 0;
}

}  // namespace

const char* toString(Mode mode) {
  return mode == Mode::kGray ? "gray" : "gray+phase";
}

Result<Mode> parseMode(const std::string& text) {
  if (text == "gray") return Mode::kGray;
  if (text == "gray+phase") return Mode::kGrayPhase;
  return fail(ErrorCode::kInvalidInput, "unknown pattern mode '" + text + "' (gray | gray+phase)");
}

Result<PatternSet> makePatternSet(const PatternOptions& o) {
  if (o.width < 1 || o.height < 1 || o.width > kMaxExtent || o.height > kMaxExtent)
    return fail(ErrorCode::kInvalidInput, "projector size must be within 1..65536 pixels");
  if (o.step < 1 || o.step > kMaxExtent || o.step_rows < 0 || o.step_rows > kMaxExtent)
    return fail(ErrorCode::kInvalidInput, "step must be a positive number of pixels");
  const int step_rows = o.step_rows > 0 ? o.step_rows : o.step;
  const bool phase = o.mode == Mode::kGrayPhase;
  // More than 64 shifts add nothing measurable over 8-16 (the phase error falls as
  // 1/sqrt(N)) and would write thousands of frames.
  if (phase && (o.phase_steps < 3 || o.phase_steps > 64))
    return fail(ErrorCode::kInvalidInput, "phase shifting takes 3 to 64 steps");
  if (phase && (o.phase_period < 4 || o.phase_period > kMaxExtent))
    return fail(ErrorCode::kInvalidInput, "phase period must be at least 4 projector pixels");
  if (!(o.projector_gamma > 0) || !std::isfinite(o.projector_gamma))
    return fail(ErrorCode::kInvalidInput, "projector gamma must be positive");

  PatternSet set;
  set.options = o;
  if (phase) {
    // Unwrapping picks the period nearest to the Gray estimate; with cell = P/4 a
    // one-cell Gray error plus half a cell of quantisation stays below P/2.
    const int period = std::max(o.phase_period, 4 * std::max(o.step, step_rows));
    const int cell = std::max(1, period / 4);
    set.options.phase_period = period;
    set.columns = makeAxis(o.width, cell, period);
    set.rows = makeAxis(o.height, cell, period);
  } else {
    set.columns = makeAxis(o.width, o.step, 0);
    set.rows = makeAxis(o.height, step_rows, 0);
  }
  set.frames.push_back({FrameKind::kWhite, Axis::kColumns, 0, frameName(0, "white")});
  set.frames.push_back({FrameKind::kBlack, Axis::kColumns, 0, frameName(1, "black")});
  addAxisFrames(set, Axis::kColumns);
  addAxisFrames(set, Axis::kRows);
  return set;
}

cv::Mat renderFrame(const PatternSet& set, std::size_t frame) {
  const FrameInfo& f = set.frames.at(frame);
  cv::Mat image(set.options.height, set.options.width, CV_8UC1);
  if (f.kind == FrameKind::kWhite || f.kind == FrameKind::kBlack) {
    image.setTo(f.kind == FrameKind::kWhite ? 255 : 0);
    return image;
  }
  if (f.axis == Axis::kColumns) {
    std::uint8_t* row0 = image.ptr<std::uint8_t>(0);
    for (int x = 0; x < image.cols; ++x) row0[x] = codeValue(set, f, x);
    for (int y = 1; y < image.rows; ++y) image.row(0).copyTo(image.row(y));
  } else {
    for (int y = 0; y < image.rows; ++y) image.row(y).setTo(codeValue(set, f, y));
  }
  return image;
}

int findFrame(const PatternSet& set, FrameKind kind, Axis axis, int index) {
  for (std::size_t i = 0; i < set.frames.size(); ++i) {
    const FrameInfo& f = set.frames[i];
    const bool axis_matters = kind != FrameKind::kWhite && kind != FrameKind::kBlack;
    if (f.kind == kind && (!axis_matters || (f.axis == axis && f.index == index)))
      return static_cast<int>(i);
  }
  return -1;
}

}  // namespace procam::sl
