#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "structured_light/apriltag_grid.hpp"

using namespace procam;
using namespace procam::sl;

TEST(AprilTagGrid, LayoutFitsTheImage) {
  auto grid = makeTagGrid({.width = 800, .height = 600});
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->module_px, 800 / (8 * 12));
  EXPECT_GE(grid->tags.size(), 4u);
  for (const auto& t : grid->tags)
    for (const Vec2& c : t.corners) {
      EXPECT_GE(c.x(), -0.5);
      EXPECT_LE(c.x(), 799.5);
      EXPECT_GE(c.y(), -0.5);
      EXPECT_LE(c.y(), 599.5);
    }
  EXPECT_FALSE(makeTagGrid({.width = 30, .height = 30, .module_px = 4}));
}

// Detected corners agree with the layout in the pixel-centre convention, seen
// directly and through a known perspective warp. The images are blurred like a
// camera's optics: on perfectly sharp synthetic edges libapriltag's edge refinement
// is biased by about -0.12 px. A wrong +0.5 px convention shift shows up in the mean.
TEST(AprilTagGrid, DetectsCornersWhereTheLayoutPutsThem) {
  auto grid = makeTagGrid({.width = 640, .height = 480, .module_px = 6});
  ASSERT_TRUE(grid);
  auto image = renderTagGrid(*grid);
  ASSERT_TRUE(image);
  const cv::Matx33d identity = cv::Matx33d::eye();
  const cv::Matx33d oblique(0.9, 0.1, 20, -0.05, 0.85, 30, 1e-4, -5e-5, 1);
  for (const cv::Matx33d& H : {identity, oblique}) {
    // cv::warpPerspective maps pixel centres as x' = H x (integer-centre convention).
    cv::Mat seen;
    cv::warpPerspective(*image, seen, H, image->size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 255);
    cv::GaussianBlur(seen, seen, cv::Size(), 1.5);
    auto found = detectTagGrid(*grid, seen);
    ASSERT_TRUE(found);
    EXPECT_GE(found->size(), 4 * grid->tags.size() - 8);
    Vec2 mean = Vec2::Zero();
    double sum = 0;
    for (const auto& c : *found) {
      const cv::Vec3d p = H * cv::Vec3d(c.pattern.x(), c.pattern.y(), 1);
      const Vec2 e = c.image - Vec2(p[0] / p[2], p[1] / p[2]);
      mean += e;
      sum += e.squaredNorm();
      EXPECT_LT(e.norm(), 0.5) << c.id << "/" << c.corner;
    }
    mean /= static_cast<double>(found->size());
    EXPECT_LT(mean.norm(), 0.05);
    EXPECT_LT(std::sqrt(sum / found->size()), 0.25);
  }
}

TEST(AprilTagGrid, RejectsColourImages) {
  auto grid = makeTagGrid({.width = 640, .height = 480});
  ASSERT_TRUE(grid);
  EXPECT_FALSE(detectTagGrid(*grid, cv::Mat(480, 640, CV_8UC3)));
}
