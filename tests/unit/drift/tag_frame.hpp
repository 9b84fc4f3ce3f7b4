#pragma once
// The drift check's fiducial frame for the unit tests: a tag grid over a framebuffer, its
// image and every tag corner drawn.
#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "structured_light/apriltag_grid.hpp"

namespace procam::drift::testing_tags {

struct TagFrame {
  sl::TagGrid grid;
  cv::Mat image;              // CV_8UC1
  std::vector<Vec2> corners;  // framebuffer pixels
};

inline std::optional<TagFrame> tagFrame(int width, int height) {
  auto grid = sl::makeTagGrid({.width = width, .height = height});
  EXPECT_TRUE(grid) << grid.error().message;
  auto image =
      grid ? sl::renderTagGrid(*grid) : Result<cv::Mat>(fail(ErrorCode::kInvalidInput, ""));
  EXPECT_TRUE(image) << image.error().message;
  if (!image) return std::nullopt;
  TagFrame f{*grid, *image, {}};
  for (const sl::TagPlacement& t : f.grid.tags)
    f.corners.insert(f.corners.end(), t.corners.begin(), t.corners.end());
  return f;
}

}  // namespace procam::drift::testing_tags
