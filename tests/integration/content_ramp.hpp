#pragma once
// A 16-bit content ramp that names every content pixel, and the error of framebuffer
// codes read back as content coordinates (procam-render's geometry checks).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "core/types.hpp"

namespace procam::itest {

// B: x ramp, G: y ramp over the content's pixel centres, R: 30000 everywhere.
inline cv::Mat contentRamp(int w, int h) {
  cv::Mat ramp(h, w, CV_16UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      ramp.at<cv::Vec3w>(y, x) = {uint16_t(std::lround(x * 65535.0 / (w - 1))),
                                  uint16_t(std::lround(y * 65535.0 / (h - 1))), 30000};
    }
  }
  return ramp;
}

struct RampError {
  int w = 0, h = 0;  // content size
  double sq = 0, worst = 0;
  long n = 0;

  // A framebuffer pixel's code against the content pixel it should show.
  void add(const cv::Vec3w& code, const Vec2& expected) {
    const double e = std::hypot(code[0] * (w - 1) / 65535.0 - expected.x(),
                                code[1] * (h - 1) / 65535.0 - expected.y());
    sq += e * e;
    worst = std::max(worst, e);
    ++n;
    EXPECT_EQ(code[2], 30000) << "a constant channel stays exact";
  }
  double rms() const { return n ? std::sqrt(sq / n) : 0; }
};

}  // namespace procam::itest
