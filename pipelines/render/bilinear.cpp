#include "render/bilinear.hpp"

#include <algorithm>
#include <cmath>

namespace procam::render {

cv::Vec4d sampleBilinear(const cv::Mat& rgba, double x, double y) {
  if (rgba.type() != CV_8UC4 || rgba.empty() || !std::isfinite(x) || !std::isfinite(y) ||
      !insideFootprint(x, y, rgba.cols, rgba.rows)) {
    return cv::Vec4d(0, 0, 0, 0);
  }
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const double ax = x - fx0, ay = y - fy0;
  const int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  const int xa = std::clamp(x0, 0, rgba.cols - 1), xb = std::clamp(x0 + 1, 0, rgba.cols - 1);
  const int ya = std::clamp(y0, 0, rgba.rows - 1), yb = std::clamp(y0 + 1, 0, rgba.rows - 1);
  const auto& p00 = rgba.at<cv::Vec4b>(ya, xa);
  const auto& p01 = rgba.at<cv::Vec4b>(ya, xb);
  const auto& p10 = rgba.at<cv::Vec4b>(yb, xa);
  const auto& p11 = rgba.at<cv::Vec4b>(yb, xb);
  cv::Vec4d out;
  for (int c = 0; c < 4; ++c) {
    const double top = p00[c] * (1 - ax) + p01[c] * ax;
    const double bottom = p10[c] * (1 - ax) + p11[c] * ax;
    out[c] = top * (1 - ay) + bottom * ay;
  }
  return out;
}

}  // namespace procam::render
