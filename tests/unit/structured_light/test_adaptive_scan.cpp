#include <gtest/gtest.h>

#include "geometry/homography.hpp"
#include "structured_light/adaptive_scan.hpp"
#include "synthetic_view.hpp"

using namespace procam;
using namespace procam::sl;
using procam::testing::kCamera;
using procam::testing::kProjH;
using procam::testing::kProjW;
using procam::testing::ViewModel;

namespace {

const cv::Matx33d kH(1.15, 0.08, 12, -0.05, 1.1, 15, 2e-4, 1e-4, 1);

CaptureFn captureWith(const ViewModel& m, int* calls) {
  return [m, calls](const PatternSet& set) -> Result<std::vector<cv::Mat>> {
    ++*calls;
    std::vector<cv::Mat> out;
    for (std::size_t i = 0; i < set.frames.size(); ++i)
      out.push_back(
          procam::testing::viewFrame(renderFrame(set, i), m, static_cast<std::uint32_t>(i)));
    return out;
  };
}

AdaptiveOptions options() {
  AdaptiveOptions o;
  o.full = {.width = kProjW, .height = kProjH, .mode = Mode::kGrayPhase, .phase_steps = 4};
  return o;
}

}  // namespace

TEST(AdaptiveScan, PlanarSurfaceStopsAfterTheCoarsePass) {
  ViewModel m;
  procam::testing::homographyMaps(kH, kCamera, m.map_x, m.map_y);
  int calls = 0;
  auto r = scanAdaptive(options(), captureWith(m, &calls));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->planar) << r->reason;
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(r->frames_used, 2 + 2 * 4 + 2 * 4);  // 16 and 12 blocks: 4 bits per axis
  EXPECT_FALSE(r->full);
  EXPECT_NE(r->reason.find("planar"), std::string::npos);
  // The homography from block correspondences maps the whole camera image to the
  // projector within the planarity tolerance.
  double worst = 0;
  for (int y = 0; y < kCamera.height; y += 7)
    for (int x = 0; x < kCamera.width; x += 7) {
      auto p = geom::applyHomography(r->coarse.H, Vec2(x, y));
      ASSERT_TRUE(p);
      worst = std::max(worst, (*p - Vec2(m.map_x.at<float>(y, x), m.map_y.at<float>(y, x))).norm());
    }
  EXPECT_LE(worst, r->coarse.tolerance_px);
}

TEST(AdaptiveScan, FoldedSurfaceGetsTheFullSet) {
  ViewModel m;
  procam::testing::homographyMaps(kH, kCamera, m.map_x, m.map_y);
  // A vertical fold (two walls meeting) at camera column 160: continuous, with a kink.
  for (int y = 0; y < kCamera.height; ++y)
    for (int x = 160; x < kCamera.width; ++x) m.map_x.at<float>(y, x) -= 0.2f * (x - 160);
  int calls = 0;
  auto r = scanAdaptive(options(), captureWith(m, &calls));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->planar) << r->reason;
  EXPECT_EQ(calls, 2);
  ASSERT_TRUE(r->full);
  auto full = makePatternSet(options().full);
  EXPECT_EQ(r->frames_used, 18 + static_cast<int>(full->frames.size()));
  EXPECT_GT(r->full->decoded, 0.9 * kCamera.area());
  EXPECT_NE(r->reason.find("non-planar"), std::string::npos);
}

TEST(AdaptiveScan, TooLittleOfTheProjectorVisibleIsAnError) {
  ViewModel m;
  procam::testing::homographyMaps(kH, kCamera, m.map_x, m.map_y);
  m.map_x.setTo(-1000);  // the camera sees nothing lit
  int calls = 0;
  auto r = scanAdaptive(options(), captureWith(m, &calls));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kTooFewPoints);
}
