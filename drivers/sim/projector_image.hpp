#pragma once
// A framebuffer as the light a projector emits: values linearised by the projector
// gamma, spread by its pixel footprint (Gaussian blur, sigma in framebuffer pixels),
// sampled bilinearly with pixel centres at integer coordinates.
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "sim/scene.hpp"

namespace procam::sim {

class ProjectorImage {
 public:
  // framebuffer: CV_8U or CV_16U, 1 (gray), 3 (BGR) or 4 (BGRA, alpha ignored)
  // channels, exactly the projector's resolution.
  static Result<ProjectorImage> create(const cv::Mat& framebuffer, const ProjectorSpec& spec);

  // Linear BGR emission at framebuffer position (x, y); the caller keeps (x, y)
  // inside [-0.5, w - 0.5) x [-0.5, h - 0.5), where edge pixels extend to the border.
  cv::Vec3f sample(double x, double y) const {
    const int w = linear_.cols, h = linear_.rows;
    const double fx = std::floor(x), fy = std::floor(y);
    const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
    const int x0 = std::clamp(static_cast<int>(fx), 0, w - 1);
    const int x1 = std::clamp(static_cast<int>(fx) + 1, 0, w - 1);
    const int y0 = std::clamp(static_cast<int>(fy), 0, h - 1);
    const int y1 = std::clamp(static_cast<int>(fy) + 1, 0, h - 1);
    const cv::Vec3f* r0 = linear_.ptr<cv::Vec3f>(y0);
    const cv::Vec3f* r1 = linear_.ptr<cv::Vec3f>(y1);
    const cv::Vec3f top = r0[x0] * (1.f - ax) + r0[x1] * ax;
    const cv::Vec3f bottom = r1[x0] * (1.f - ax) + r1[x1] * ax;
    return top * (1.f - ay) + bottom * ay;
  }

  const cv::Mat& linear() const { return linear_; }  // CV_32FC3

 private:
  cv::Mat linear_;
};

}  // namespace procam::sim
