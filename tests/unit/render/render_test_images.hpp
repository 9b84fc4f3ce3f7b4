#pragma once
// Test content shared by the render and output tests: images with known gradients and
// image-difference measures.
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>

namespace procam::test {

// Smooth RGBA content: channel c = 127.5 + 127.5 sin(kx x + ky y + phase_c). Largest
// neighbour difference per axis <= 127.5 * k (k in radians per pixel).
inline cv::Mat smoothImage(cv::Size size, double kx, double ky) {
  cv::Mat img(size, CV_8UC4);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      cv::Vec4b& p = img.at<cv::Vec4b>(y, x);
      for (int c = 0; c < 3; ++c) {
        p[c] =
            static_cast<uint8_t>(std::lround(127.5 + 127.5 * std::sin(kx * x + ky * y + 2.0 * c)));
      }
      p[3] = 255;
    }
  }
  return img;
}

// Detailed content: smooth shading plus a grid of lines and a checkerboard, opaque.
inline cv::Mat detailedImage(cv::Size size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> d(0, 255);
  cv::Mat img = smoothImage(size, 0.11, 0.07);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      cv::Vec4b& p = img.at<cv::Vec4b>(y, x);
      if (x % 16 == 0 || y % 16 == 0) p = cv::Vec4b(255, 255, 255, 255);
      if (((x / 32) + (y / 32)) % 2 == 0) p[2] = static_cast<uint8_t>(p[2] / 2);
      if (d(rng) < 8) p[1] = static_cast<uint8_t>(d(rng));
    }
  }
  return img;
}

inline cv::Mat randomImage(cv::Size size, uint32_t seed) {
  cv::Mat img(size, CV_8UC4);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  return img;
}

struct Difference {
  double mean_abs = 0;  // in code values, over compared pixels and channels
  double max_abs = 0;
  double psnr = 0;  // dB, peak 255; infinity when identical
  long pixels = 0;
};

// Compares a and b (CV_8UC4) where mask (CV_8UC1) is non-zero, colour channels only.
inline Difference compare(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  Difference d;
  double sum = 0, sq = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      if (!mask.empty() && mask.at<uint8_t>(y, x) == 0) continue;
      const cv::Vec4b& p = a.at<cv::Vec4b>(y, x);
      const cv::Vec4b& q = b.at<cv::Vec4b>(y, x);
      for (int c = 0; c < 3; ++c) {
        const double e = std::abs(double(p[c]) - double(q[c]));
        sum += e;
        sq += e * e;
        d.max_abs = std::max(d.max_abs, e);
      }
      ++d.pixels;
    }
  }
  const double n = 3.0 * static_cast<double>(std::max<long>(d.pixels, 1));
  d.mean_abs = sum / n;
  d.psnr = sq == 0 ? INFINITY : 10.0 * std::log10(255.0 * 255.0 / (sq / n));
  return d;
}

}  // namespace procam::test
