#pragma once
// The fiducial frame of a drift check (drift/fiducial_misregistration.hpp): a grid of
// AprilTags (tag36h11) over the whole framebuffer, shown for one check when the content
// is too plain to register, and the tag corners a camera finds in it. Built without
// libapriltag, makeFiducialFrame says so and the daemon checks content only.
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <tl/expected.hpp>
#include <vector>

#include "drift/fiducial_misregistration.hpp"
#include "structured_light/apriltag_grid.hpp"

namespace procam::daemon {

struct FiducialFrame {
  sl::TagGrid grid;
  cv::Mat rgb;                // CV_8UC3, the framebuffer's size
  std::vector<Vec2> corners;  // every tag corner drawn, framebuffer pixels
};

// For a framebuffer of `size`; the reason when none can be made.
tl::expected<std::shared_ptr<const FiducialFrame>, std::string> makeFiducialFrame(cv::Size size);

// The tag corners found in `grey` (one channel, any depth: deeper than 8 bits it is
// stretched over its range), each with the framebuffer pixel it was drawn at.
tl::expected<std::vector<drift::FiducialCorner>, std::string> findFiducials(
    const FiducialFrame& frame, const cv::Mat& grey);

}  // namespace procam::daemon
