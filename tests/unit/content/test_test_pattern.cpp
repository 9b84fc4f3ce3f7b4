// The alignment patterns (grid, crosshair, flat fields) and their source.
#include <gtest/gtest.h>

#include "content/still_sources.hpp"
#include "content/test_pattern.hpp"

namespace procam::content {
namespace {

TEST(TestPattern, GridCrosshairAndFlatFields) {
  const RgbImage grid = renderTestPattern("grid", 257, 129, 64);
  // Centre lines through (128, 64), then every 64 px from the centre, and borders.
  for (int x : {0, 64, 128, 192, 256}) EXPECT_EQ(grid.at(x, 10, 0), 255) << x;
  for (int x : {1, 63, 65, 200}) EXPECT_EQ(grid.at(x, 10, 1), 0) << x;
  for (int y : {0, 64, 128}) EXPECT_EQ(grid.at(10, y, 2), 255) << y;
  const RgbImage cross = renderTestPattern("crosshair", 257, 129);
  EXPECT_EQ(cross.at(128, 30, 0), 255);
  EXPECT_EQ(cross.at(64, 30, 0), 0);  // no grid lines
  EXPECT_EQ(renderTestPattern("white", 4, 4).at(2, 2, 1), 255);
  EXPECT_EQ(renderTestPattern("black", 4, 4).at(2, 2, 1), 0);
  EXPECT_EQ(renderTestPattern("off", 4, 4).at(0, 0, 1), 0);
}

TEST(TestPattern, SourceYieldsThePatternOnceThenEnds) {
  auto source = openTestPattern("grid", {257, 129});
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->size(), cv::Size(257, 129));
  EXPECT_EQ((*source)->format(), PixelFormat::kRgb8);
  EXPECT_EQ((*source)->pollFd(), -1);
  Frame f;
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  const RgbImage want = renderTestPattern("grid", 257, 129);
  ASSERT_EQ(f.pixels.type(), CV_8UC3);
  EXPECT_EQ(0, std::memcmp(f.pixels.data, want.pixels.data(), want.pixels.size()));
  EXPECT_EQ(f.sequence, 1u);
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kEnd);
  EXPECT_FALSE(openTestPattern("plaid", {8, 8}));
  EXPECT_FALSE(openTestPattern("grid", {1, 8}));
}

}  // namespace
}  // namespace procam::content
