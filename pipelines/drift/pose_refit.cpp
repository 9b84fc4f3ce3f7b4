#include "pose_refit.hpp"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "calibration/opencv_camera.hpp"

namespace procam::drift {

Result<PoseRefit> refitPose(const geom::CameraModel& before, const std::vector<Vec3>& world,
                            const std::vector<Vec2>& pixels) {
  if (world.size() != pixels.size()) {
    return fail(ErrorCode::kInvalidInput, "pose refit: as many image as world points needed");
  }
  if (world.size() < 4) return fail(ErrorCode::kTooFewPoints, "pose refit: at least 4 points");
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (std::size_t i = 0; i < world.size(); ++i) {
    if (!world[i].allFinite() || !pixels[i].allFinite()) {
      return fail(ErrorCode::kInvalidInput, "pose refit: a point is not finite");
    }
    object.emplace_back(world[i].x(), world[i].y(), world[i].z());
    image.emplace_back(pixels[i].x(), pixels[i].y());
  }
  const cv::Mat K = calib::detail::cameraMatrix(before), dist = calib::detail::distCoeffs(before);
  cv::Mat R, rvec, tvec;
  cv::eigen2cv(Mat3(before.pose.R), R);
  cv::Rodrigues(R, rvec);
  cv::eigen2cv(Vec3(before.pose.t), tvec);
  if (!cv::solvePnP(object, image, K, dist, rvec, tvec, true, cv::SOLVEPNP_ITERATIVE)) {
    return fail(ErrorCode::kNoConvergence, "pose refit: the solver did not converge");
  }
  PoseRefit out;
  out.pose = calib::detail::poseFromRvec(rvec, tvec);
  std::vector<cv::Point2d> back;
  cv::projectPoints(object, rvec, tvec, K, dist, back);
  double sq = 0;
  for (std::size_t i = 0; i < back.size(); ++i) {
    sq += std::pow(back[i].x - image[i].x, 2) + std::pow(back[i].y - image[i].y, 2);
  }
  out.rms_px = std::sqrt(sq / static_cast<double>(back.size()));
  if (!out.pose.R.allFinite() || !out.pose.t.allFinite() || !std::isfinite(out.rms_px)) {
    return fail(ErrorCode::kNoConvergence, "pose refit: the pose is not finite");
  }
  return out;
}

}  // namespace procam::drift
