#pragma once
// Plane-to-plane homographies ([Raskar02] §3.2.5, §4.2.1): dst ~ H * src.
#include <array>
#include <optional>
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::geom {

struct HomographyFit {
  Mat3 H = Mat3::Identity();  // normalised so that ||H||_F = 1 and H(2,2) >= 0
  double condition = 0;       // condition number of the normalised DLT system (σ1/σ8)
  double rms = 0;             // RMS of ||dst - H src|| in dst pixels
  int iterations = 0;         // LM iterations (0 for pure DLT)
};

struct HomographyOptions {
  bool refine = true;  // Levenberg-Marquardt on the dst-side geometric error
  int max_iterations = 50;
  // Larger -> kIllConditioned. Exact data then gives H to ~cond·1e-16 relative; well
  // spread points give cond ~ 1e1..1e3 after normalisation.
  double max_condition = 1e8;
};

// Applies H to a point; nullopt when the point maps to infinity.
std::optional<Vec2> applyHomography(const Mat3& H, const Vec2& p);

// All estimators: kInvalidInput for NaN/Inf, coordinates beyond 1e100 or differing
// lengths; kTooFewPoints below 4; kDegenerate for coincident/collinear configurations.

// Exact solve from four correspondences; kDegenerate when any three are collinear.
Result<Mat3> homographyFrom4(const std::array<Vec2, 4>& src, const std::array<Vec2, 4>& dst);

// Hartley-normalised DLT for n >= 4 (no refinement).
Result<HomographyFit> fitHomographyDlt(std::span<const Vec2> src, std::span<const Vec2> dst,
                                       const HomographyOptions& options = {});

// LM refinement of the geometric error in the dst image (the ML estimate when
// noise is only in dst).
Result<HomographyFit> refineHomography(const Mat3& H0, std::span<const Vec2> src,
                                       std::span<const Vec2> dst,
                                       const HomographyOptions& options = {});

// DLT followed, if options.refine, by LM (not for n = 4: the DLT is then exact).
Result<HomographyFit> fitHomography(std::span<const Vec2> src, std::span<const Vec2> dst,
                                    const HomographyOptions& options = {});

}  // namespace procam::geom
