// procamd built without libapriltag: no fiducial frame; the drift check registers
// content only (plain content is reported too plain to tell).
#include "drift_fiducial.hpp"

namespace procam::daemon {

tl::expected<std::shared_ptr<const FiducialFrame>, std::string> makeFiducialFrame(cv::Size) {
  return tl::unexpected(std::string("procamd was built without libapriltag: no fiducial frame"));
}

tl::expected<std::vector<drift::FiducialCorner>, std::string> findFiducials(const FiducialFrame&,
                                                                            const cv::Mat&) {
  return tl::unexpected(std::string("procamd was built without libapriltag"));
}

}  // namespace procam::daemon
