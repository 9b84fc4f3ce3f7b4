#pragma once
// The shader-lamp tests' texture: three slow waves, every channel in [0.2, 0.85] of linear
// light, smooth enough that a pixel's footprint does not blur it.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <opencv2/core.hpp>

namespace procam::itest {

// Linear RGB at texture coordinate (u, v), v up.
inline cv::Vec3d waveAt(double u, double v) {
  const double pi = std::numbers::pi;
  return {0.55 + 0.3 * std::sin(2 * pi * (2 * u + v)), 0.5 + 0.3 * std::cos(2 * pi * (u - 2 * v)),
          0.45 + 0.25 * std::sin(6 * pi * v)};
}

// As a material's texture: CV_32FC3, linear RGB, n x n.
inline cv::Mat waveTextureLinear(int n = 256) {
  cv::Mat t(n, n, CV_32FC3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) t.at<cv::Vec3f>(y, x) = waveAt((x + 0.5) / n, 1 - (y + 0.5) / n);
  return t;
}

// As an image file holds it: CV_8UC3, sRGB-encoded, BGR (OpenCV's order), n x n.
inline cv::Mat waveTextureSrgb(int n = 256) {
  cv::Mat t(n, n, CV_8UC3);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const cv::Vec3d rgb = waveAt((x + 0.5) / n, 1 - (y + 0.5) / n);
      for (int c = 0; c < 3; ++c) {
        const double l = rgb[c];
        const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
        t.at<cv::Vec3b>(y, x)[2 - c] = static_cast<std::uint8_t>(std::lround(255 * e));
      }
    }
  }
  return t;
}

}  // namespace procam::itest
