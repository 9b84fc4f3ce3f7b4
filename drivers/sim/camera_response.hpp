#pragma once
// The camera's sensor and encoder (SCENE-FORMAT.md, "Camera signal chain"):
// radiance -> exposure -> electrons (full-well saturation, shot noise) -> gain
// -> read noise -> response gamma -> quantisation to the bit depth.
#include <cstdint>
#include <opencv2/core.hpp>

#include "sim/scene.hpp"

namespace procam::sim {

class CameraResponse {
 public:
  CameraResponse(const CameraSpec& spec, bool noise) : spec_(spec), noise_(noise) {}

  // Output image type: CV_8U for <= 8 bits, CV_16U above; 1 or 3 channels.
  int outputType() const;

  // Converts one row of mean radiance (BGR, linear) into codes, drawing noise from
  // a generator seeded by (seed, row) so the result does not depend on threading.
  void convertRow(const cv::Vec3f* radiance, int row, std::uint64_t seed, cv::Mat& out) const;

 private:
  const CameraSpec& spec_;
  bool noise_;
};

// Luminance of a gray camera from linear BGR (Rec. 709 weights).
inline float luminance(const cv::Vec3f& bgr) {
  return 0.0722f * bgr[0] + 0.7152f * bgr[1] + 0.2126f * bgr[2];
}

}  // namespace procam::sim
