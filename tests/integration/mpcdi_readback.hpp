#pragma once
// An MPCDI package read back and drawn as a 2D-profile player draws it, against
// procam-render's own 16-bit framebuffers.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "blend/mpcdi.hpp"
#include "mpcdi_zip.hpp"

namespace procam::itest {

// The largest difference, in 8-bit code values, between the frame a player draws for
// each region of `package` from `content` and the 16-bit frame `frames`/ID.png; every
// region must show content and there must be `regions` of them. -1 (with a test failure)
// when the package cannot be read.
inline double mpcdiDifference(const std::string& package, const std::string& frames,
                              const cv::Mat& content, std::size_t regions) {
  auto files = render_cli::readMpcdiZip(package);
  EXPECT_TRUE(files) << files.error().message;
  if (!files) return -1;
  EXPECT_EQ(files->front().name, "mpcdi.xml");
  auto display = blend::readMpcdi2d(*files);
  EXPECT_TRUE(display) << display.error().message;
  if (!display) return -1;
  EXPECT_EQ(display->buffer, content.size());
  EXPECT_EQ(display->regions.size(), regions);
  double worst = 0;
  for (const blend::MpcdiRegion& region : display->regions) {
    const cv::Mat frame = cv::imread(frames + "/" + region.id + ".png", cv::IMREAD_UNCHANGED);
    EXPECT_EQ(frame.type(), CV_16UC3) << region.id;
    auto rebuilt = blend::mpcdiFrame(region, content);
    EXPECT_TRUE(rebuilt) << rebuilt.error().message;
    if (!rebuilt || frame.type() != CV_16UC3 || rebuilt->size() != frame.size()) return -1;
    cv::Mat diff;
    cv::absdiff(*rebuilt, frame, diff);
    double max_diff = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
    worst = std::max(worst, max_diff / 257.0);
    EXPECT_GT(cv::countNonZero(frame.reshape(1)), 0) << region.id << " shows content";
  }
  return worst;
}

}  // namespace procam::itest
