#include "drift_fiducial.hpp"

#include <opencv2/imgproc.hpp>

namespace procam::daemon {

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
  auto found = sl::detectTagGrid(frame.grid, grey);
  if (!found) return tl::unexpected("the fiducial frame's tags: " + found.error().message);
  std::vector<drift::FiducialCorner> out;
  out.reserve(found->size());
  for (const sl::TagCorrespondence& c : *found) out.push_back({c.pattern, c.image});
  return out;
}

}  // namespace procam::daemon
