#include "shown_light.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace procam::drift {

Result<cv::Mat> shownLight(const cv::Mat& frame, double gamma, const WorkGrid& grid) {
  if ((frame.type() != CV_8UC1 && frame.type() != CV_8UC4) || frame.size() != grid.framebuffer ||
      grid.size().empty()) {
    return fail(ErrorCode::kInvalidInput,
                "drift check: the frame must be 8-bit grey or RGBA of the framebuffer's size");
  }
  if (!(gamma >= 1 && gamma <= 4)) {
    return fail(ErrorCode::kInvalidInput, "drift check: a projector response outside [1, 4]");
  }
  cv::Mat light_of(1, 256, CV_32F);
  for (int c = 0; c < 256; ++c) {
    light_of.at<float>(c) = static_cast<float>(255.0 * std::pow(c / 255.0, gamma));
  }
  cv::Mat light, grey, out;
  if (frame.channels() == 1) {
    cv::LUT(frame, light_of, grey);
  } else {
    cv::Mat rgb;
    cv::cvtColor(frame, rgb, cv::COLOR_RGBA2RGB);
    cv::LUT(rgb, light_of, light);
    cv::cvtColor(light, grey, cv::COLOR_RGB2GRAY);
  }
  cv::resize(grey, out, grid.size(), 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace procam::drift
