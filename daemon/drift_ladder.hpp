#pragma once
// The steps recalibrate = "on-drift" climbs when drift is not corrected: corrections
// from the content (the projector's or a camera's pose, the wall's plane), then scans of
// the projector, each only when the cheaper one failed its check.
#include <optional>

#include "config.hpp"

namespace procam::daemon {

// Corrections from the content in a row that did not bring the misregistration under the
// threshold before the daemon tries a scan, or stops trying (the projector keeps moving,
// or what changed is not a pose: a surface, a zoom).
inline constexpr int kMaxDriftPasses = 3;

// The scans a drift correction escalates to when the content's steps fail their check.
enum class DriftScan { kNone, kCoarse, kFull };

// The step a scan is reported as (drift events, status).
inline const char* driftScanName(DriftScan scan) {
  return scan == DriftScan::kCoarse ? "coarse-scan" : scan == DriftScan::kFull ? "full-scan" : "";
}

// The scan to make after `made` (kNone: only content corrections so far) failed its
// check: the coarse Gray pass, then the full scan; none after the full scan, nor under a
// policy that shows no pattern frames.
inline std::optional<DriftScan> nextDriftScan(DriftScan made, RecalibratePolicy policy) {
  if (policy != RecalibratePolicy::kOnDrift) return std::nullopt;
  if (made == DriftScan::kNone) return DriftScan::kCoarse;
  if (made == DriftScan::kCoarse) return DriftScan::kFull;
  return std::nullopt;
}

}  // namespace procam::daemon
