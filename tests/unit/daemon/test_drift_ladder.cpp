// The steps recalibrate = "on-drift" climbs when drift is not corrected (drift_ladder.hpp).
#include <gtest/gtest.h>

#include "drift_ladder.hpp"

namespace procam::daemon {
namespace {

TEST(DriftLadder, ScansOnlyAfterTheCheaperStepFailedAndOnlyWhenFramesMayBeShown) {
  using P = RecalibratePolicy;
  // After the content's corrections: the coarse pass; after it, the full scan; then none.
  EXPECT_EQ(nextDriftScan(DriftScan::kNone, P::kOnDrift), DriftScan::kCoarse);
  EXPECT_EQ(nextDriftScan(DriftScan::kCoarse, P::kOnDrift), DriftScan::kFull);
  EXPECT_EQ(nextDriftScan(DriftScan::kFull, P::kOnDrift), std::nullopt);
  // "on-drift-silent" never shows a pattern frame, "off" never corrects.
  for (P p : {P::kOnDriftSilent, P::kOff}) {
    for (DriftScan made : {DriftScan::kNone, DriftScan::kCoarse, DriftScan::kFull}) {
      EXPECT_EQ(nextDriftScan(made, p), std::nullopt);
    }
  }
  EXPECT_STREQ(driftScanName(DriftScan::kCoarse), "coarse-scan");
  EXPECT_STREQ(driftScanName(DriftScan::kFull), "full-scan");
  EXPECT_STREQ(driftScanName(DriftScan::kNone), "");
}

}  // namespace
}  // namespace procam::daemon
