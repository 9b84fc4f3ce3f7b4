#include "drift_fiducial.hpp"

#include <opencv2/imgproc.hpp>

namespace procam::daemon {

namespace {

// The camera's image as 8 bits for the detector: 8-bit values as they are, deeper ones
// (a 16-bit camera, or a mean of frames beyond 255) stretched over their range.
cv::Mat eightBit(const cv::Mat& grey) {
  if (grey.type() == CV_8UC1) return grey;
  double lo = 0, hi = 0;
  cv::minMaxLoc(grey, &lo, &hi);
  cv::Mat out;
  if (lo >= 0 && hi <= 255) {
    grey.convertTo(out, CV_8U);
  } else {
    cv::normalize(grey, out, 0, 255, cv::NORM_MINMAX, CV_8U);
  }
  return out;
}

}  // namespace

tl::expected<std::shared_ptr<const FiducialFrame>, std::string> makeFiducialFrame(cv::Size size) {
  auto grid = sl::makeTagGrid({.width = size.width, .height = size.height});
  if (!grid) return tl::unexpected("the fiducial frame: " + grid.error().message);
  auto image = sl::renderTagGrid(*grid);
  if (!image) return tl::unexpected("the fiducial frame: " + image.error().message);
  auto frame = std::make_shared<FiducialFrame>();
  frame->grid = std::move(*grid);
  cv::cvtColor(*image, frame->rgb, cv::COLOR_GRAY2RGB);
  for (const sl::TagPlacement& t : frame->grid.tags) {
    frame->corners.insert(frame->corners.end(), t.corners.begin(), t.corners.end());
  }
  return frame;
}

tl::expected<std::vector<drift::FiducialCorner>, std::string> findFiducials(
    const FiducialFrame& frame, const cv::Mat& grey) {
  if (grey.empty() || grey.channels() != 1) {
    return tl::unexpected(std::string("the fiducial frame's tags: not a grey image"));
  }
  auto found = sl::detectTagGrid(frame.grid, eightBit(grey));
  if (!found) return tl::unexpected("the fiducial frame's tags: " + found.error().message);
  std::vector<drift::FiducialCorner> out;
  out.reserve(found->size());
  for (const sl::TagCorrespondence& c : *found) out.push_back({c.pattern, c.image});
  return out;
}

}  // namespace procam::daemon
