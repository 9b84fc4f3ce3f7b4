// Tests for pipelines/tracking/tracker_registration: tracker -> world from 6 measured
// points (<= 1 mm RMS), the screen-defined frame of [Raskar02] §4.2.5, typed errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "tracking/tracker_registration.hpp"

namespace procam::tracking {
namespace {

TEST(TrackerRegistration, SixPointsWithinOneMillimetre) {
  std::mt19937_64 rng(31);
  // Tracker noise 0.5 mm per axis (0.9 mm 3D, about the stereo figure of this pipeline).
  std::normal_distribution<double> n(0, 0.5e-3);
  const Mat3 R = (Eigen::AngleAxisd(0.4, Vec3::UnitZ()) * Eigen::AngleAxisd(-1.1, Vec3::UnitX()))
                     .toRotationMatrix();
  const Vec3 t(0.8, -0.3, 1.9);
  // Six world points spread over a 2 m x 1.5 m room volume (screen corners, floor marks).
  const Points3 world = {Vec3(-1, 0, 0),  Vec3(1, 0, 0),     Vec3(-1, 1.5, 0),
                         Vec3(1, 1.5, 0), Vec3(0, 0.2, 1.2), Vec3(0.5, 1.0, 0.8)};
  Points3 tracker;
  for (const Vec3& w : world)
    tracker.push_back(R.transpose() * (w - t) + Vec3(n(rng), n(rng), n(rng)));
  auto reg = registerTracker(tracker, world);
  ASSERT_TRUE(reg) << reg.error().message;
  // Error of the registration itself, at points away from the measured ones too.
  double worst = 0;
  for (const Vec3& p : {Vec3(0, 0.7, 2.0), Vec3(-0.8, 1.2, 1.5), Vec3(0.9, 0.1, 0.3)}) {
    const Vec3 trk = R.transpose() * (p - t);
    worst = std::max(worst, (reg->toWorld(trk) - p).norm());
  }
  std::printf("registration error %.3f mm, residual RMS %.3f mm\n", worst * 1e3, reg->rms * 1e3);
  EXPECT_LE(worst, 1e-3);
  EXPECT_LT(reg->rms, 2e-3);
}

TEST(TrackerRegistration, SimilarityRecoversAScaledTracker) {
  const Points3 world = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)};
  Points3 tracker;
  for (const Vec3& w : world) tracker.push_back(w / 0.0254);  // tracker in inches
  auto reg = registerTracker(tracker, world, true);
  ASSERT_TRUE(reg);
  EXPECT_NEAR(reg->scale, 0.0254, 1e-12);
}

TEST(TrackerRegistration, TypedErrorsForTooFewAndCollinear) {
  const Points3 three = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  EXPECT_EQ(registerTracker(three, three).error().code, ErrorCode::kTooFewPoints);
  const Points3 line = {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3), Vec3(5, 5, 5)};
  EXPECT_EQ(registerTracker(line, line).error().code, ErrorCode::kDegenerate);
}

TEST(TrackerRegistration, ScreenPointsDefineTheWorldFrame) {
  // Screen z = 0 in world, viewer at +z; tracker frame rotated and shifted.
  const Mat3 R = (Eigen::AngleAxisd(0.3, Vec3::UnitY()) * Eigen::AngleAxisd(2.0, Vec3::UnitZ()))
                     .toRotationMatrix();
  const Vec3 t(-0.4, 0.2, 3.0);
  const Points3 world = {Vec3(0, 0, 0), Vec3(1.2, 0, 0), Vec3(-1.0, 0.7, 0), Vec3(0.4, -0.6, 0),
                         Vec3(1.0, 0.9, 0)};
  Points3 tracker;
  for (const Vec3& w : world) tracker.push_back(R.transpose() * (w - t));
  const Vec3 viewer_trk = R.transpose() * (Vec3(0, 0, 2) - t);
  auto reg = registerTrackerToScreen(tracker, 0, 1, viewer_trk);
  ASSERT_TRUE(reg) << reg.error().message;
  for (size_t i = 0; i < world.size(); ++i)
    EXPECT_LT((reg->toWorld(tracker[i]) - world[i]).norm(), 1e-12);
  EXPECT_NEAR(reg->tracker_to_world.R.determinant(), 1.0, 1e-12);
  EXPECT_EQ(registerTrackerToScreen(tracker, 0, 0, viewer_trk).error().code,
            ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::tracking
