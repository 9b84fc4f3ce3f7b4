#pragma once
// Synthetic head trajectory for the LED tracker's tests and bench: a cap
// constellation with LEDs ~6 cm apart, 2 m in front of one camera, swaying and turning.
// Camera f = 4000 px on a 1280x1024 sensor: positionCovariance's bound for this layout
// at 2 m with 0.1 px blob noise is below 1.5 mm there, and above 2 mm at f = 1000 px
// (see tests/unit/tracking/test_constellation_pose.cpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/core/mat.hpp>
#include <span>
#include <vector>

#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::tracking::synthetic {

// Asymmetric, non-coplanar (m, constellation frame, origin between the eyes).
inline const Points3 kCapLeds = {Vec3(-0.06, 0, 0), Vec3(0, 0, 0.0), Vec3(0.06, 0, 0),
                                 Vec3(0, -0.06, 0.02), Vec3(0.03, -0.05, -0.03)};

inline constexpr double kCapCameraF = 4000;

// At the world origin looking along +z.
inline geom::CameraModel capCamera(double f = kCapCameraF) {
  geom::CameraModel c;
  c.K = {f, f, 639.5, 511.5, 0};
  c.width = 1280;
  c.height = 1024;
  c.pose = geom::Pose::lookAt(Vec3::Zero(), Vec3(0, 0, 2), Vec3(0, 1, 0));
  return c;
}

struct HeadPose {
  Mat3 R;  // constellation -> world
  Vec3 t;  // constellation origin, world
  Vec3 led(size_t i) const { return R * kCapLeds[i] + t; }
};

// Head swaying 0.1 m at 0.5 Hz in x, 3 cm at 0.3 Hz in y, turning +-10 deg at 0.4 Hz,
// LEDs facing the camera (-z).
inline HeadPose headAt(double t) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  const Mat3 R = (Eigen::AngleAxisd(0.17 * std::sin(kTwoPi * 0.4 * t), Vec3::UnitY()) *
                  Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitY()))
                     .toRotationMatrix();
  return HeadPose{R,
                  Vec3(0.1 * std::sin(kTwoPi * 0.5 * t), 0.03 * std::sin(kTwoPi * 0.3 * t), 2.0)};
}

// A gray8 IR frame: black, with a Gaussian spot (sigma 1.5 px, peak 200 DN, pixel
// centres at integers) at each centre.
inline cv::Mat renderSpots(int width, int height, const Points2& centres) {
  cv::Mat img(height, width, CV_8UC1, cv::Scalar(0));
  for (const Vec2& c : centres) {
    const int x0 = static_cast<int>(std::round(c.x())), y0 = static_cast<int>(std::round(c.y()));
    for (int y = std::max(0, y0 - 6); y <= std::min(height - 1, y0 + 6); ++y)
      for (int x = std::max(0, x0 - 6); x <= std::min(width - 1, x0 + 6); ++x) {
        const double r2 = (x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y());
        const double v = img.at<uint8_t>(y, x) + 200 * std::exp(-r2 / (2 * 1.5 * 1.5));
        img.at<uint8_t>(y, x) = static_cast<uint8_t>(std::min(255.0, std::round(v)));
      }
  }
  return img;
}

// Time shift s (s, grid of 0.1 ms within +-0.1 s) minimising sum |x_i - truth(t_i - s)|^2
// on the x axis: the lag of a tracked signal behind the truth.
template <class Truth>
double lagBehind(std::span<const double> times, std::span<const double> xs, Truth truth_x) {
  double best = 1e300, lag = 0;
  for (int k = -1000; k <= 1000; ++k) {
    const double s = k * 1e-4;
    double e = 0;
    for (size_t i = 0; i < times.size(); ++i) {
      const double d = xs[i] - truth_x(times[i] - s);
      e += d * d;
    }
    if (e < best) {
      best = e;
      lag = s;
    }
  }
  return lag;
}

}  // namespace procam::tracking::synthetic
