#pragma once
// A camera looking at the projector's image through a known mapping, for decoder
// tests that do not need the full virtual rig: the projector frame goes through the
// projector's response (gamma), an optional defocus blur, is sampled at the mapped
// position of every camera pixel, gets ambient light, read noise and quantisation.
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

namespace procam::testing {

// The decoder tests' projector and camera sizes: a 400 x 300 projector seen obliquely.
inline constexpr int kProjW = 400, kProjH = 300;
inline const cv::Size kCamera(320, 240);

struct ViewModel {
  cv::Mat map_x, map_y;          // CV_32F: projector coordinate seen by each camera pixel
  double projector_gamma = 2.2;  // projector response: radiance = (value/255)^gamma
  double defocus_sigma = 0;      // projector-pixel Gaussian blur
  double gain = 0.8;             // full-white radiance in units of camera full scale
  double ambient = 0.1;          // fraction of full scale
  double noise_dn = 1.0;         // read noise sigma, in DN of the output depth
  double camera_gamma = 1.0;     // camera encoding: output = signal^(1/camera_gamma)
  bool sixteen_bit = false;
  std::uint32_t seed = 7;
};

inline cv::Mat viewFrame(const cv::Mat& projector_frame, const ViewModel& m, std::uint32_t salt) {
  cv::Mat radiance;
  projector_frame.convertTo(radiance, CV_32F, 1.0 / 255.0);
  cv::pow(radiance, m.projector_gamma, radiance);
  if (m.defocus_sigma > 0) cv::GaussianBlur(radiance, radiance, cv::Size(), m.defocus_sigma);
  cv::Mat seen;
  cv::remap(radiance, seen, m.map_x, m.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  const double full = m.sixteen_bit ? 65535.0 : 255.0;
  std::mt19937 rng(m.seed * 7919u + salt);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(m.noise_dn));
  cv::Mat out(seen.size(), m.sixteen_bit ? CV_16UC1 : CV_8UC1);
  for (int y = 0; y < seen.rows; ++y) {
    const float* s = seen.ptr<float>(y);
    for (int x = 0; x < seen.cols; ++x) {
      const double signal =
          std::pow(std::min(1.0, m.ambient + m.gain * s[x]), 1.0 / m.camera_gamma);
      const double v = signal * full + noise(rng);
      const double q = std::clamp(std::round(v), 0.0, full);
      if (m.sixteen_bit)
        out.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(q);
      else
        out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(q);
    }
  }
  return out;
}

// Camera pixel (x, y) sees projector point H * (x, y, 1).
inline void homographyMaps(const cv::Matx33d& H, cv::Size camera, cv::Mat& map_x, cv::Mat& map_y) {
  map_x.create(camera, CV_32F);
  map_y.create(camera, CV_32F);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const cv::Vec3d p = H * cv::Vec3d(x, y, 1);
      map_x.at<float>(y, x) = static_cast<float>(p[0] / p[2]);
      map_y.at<float>(y, x) = static_cast<float>(p[1] / p[2]);
    }
}

}  // namespace procam::testing
