#include "sim/projector_image.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace procam::sim {

Result<ProjectorImage> ProjectorImage::create(const cv::Mat& framebuffer,
                                              const ProjectorSpec& spec) {
  if (framebuffer.cols != spec.width || framebuffer.rows != spec.height)
    return fail(ErrorCode::kInvalidInput, "framebuffer for projector '" + spec.name + "' is " +
                                              std::to_string(framebuffer.cols) + "x" +
                                              std::to_string(framebuffer.rows) +
                                              ", the projector is " + std::to_string(spec.width) +
                                              "x" + std::to_string(spec.height));
  const int depth = framebuffer.depth();
  const int channels = framebuffer.channels();
  if ((depth != CV_8U && depth != CV_16U) || (channels != 1 && channels != 3 && channels != 4))
    return fail(ErrorCode::kInvalidInput, "framebuffer for projector '" + spec.name +
                                              "' must be 8- or 16-bit with 1, 3 or 4 channels");

  // Look-up table: code value -> (code / max)^gamma.
  const int levels = depth == CV_8U ? 256 : 65536;
  std::vector<float> lut(static_cast<std::size_t>(levels));
  for (int i = 0; i < levels; ++i)
    lut[static_cast<std::size_t>(i)] =
        static_cast<float>(std::pow(static_cast<double>(i) / (levels - 1), spec.gamma));

  ProjectorImage image;
  image.linear_.create(framebuffer.rows, framebuffer.cols, CV_32FC3);
  for (int y = 0; y < framebuffer.rows; ++y) {
    cv::Vec3f* out = image.linear_.ptr<cv::Vec3f>(y);
    for (int x = 0; x < framebuffer.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int src_c = channels == 1 ? 0 : c;
        const int code = depth == CV_8U ? framebuffer.ptr<std::uint8_t>(y)[x * channels + src_c]
                                        : framebuffer.ptr<std::uint16_t>(y)[x * channels + src_c];
        out[x][c] = lut[static_cast<std::size_t>(code)];
      }
    }
  }
  if (spec.blur_sigma_px > 0) {
    // Light spreads in linear units; nothing is emitted beyond the frame.
    cv::GaussianBlur(image.linear_, image.linear_, cv::Size(0, 0), spec.blur_sigma_px,
                     spec.blur_sigma_px, cv::BORDER_CONSTANT);
  }
  return image;
}

}  // namespace procam::sim
