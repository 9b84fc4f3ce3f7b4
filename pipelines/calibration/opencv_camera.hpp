#pragma once
// A camera model in OpenCV's calib3d form (camera matrix, k1 k2 p1 p2 k3) and
// poses back from rotation vectors: what the calibration pipelines hand to and take
// from cv::calibrateCamera, cv::stereoCalibrate and cv::solvePnP.
#include <opencv2/calib3d.hpp>

#include "geometry/camera_model.hpp"

namespace procam::calib::detail {

inline cv::Mat cameraMatrix(const geom::CameraModel& c) {
  cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  K.at<double>(0, 0) = c.K.fx;
  K.at<double>(0, 1) = c.K.skew;
  K.at<double>(0, 2) = c.K.cx;
  K.at<double>(1, 1) = c.K.fy;
  K.at<double>(1, 2) = c.K.cy;
  return K;
}

inline cv::Mat distCoeffs(const geom::CameraModel& c) {
  return (cv::Mat_<double>(1, 5) << c.dist.k1, c.dist.k2, c.dist.p1, c.dist.p2, c.dist.k3);
}

inline geom::Pose poseFromMatrix(const cv::Mat& R, const cv::Mat& tvec) {
  geom::Pose p;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) p.R(r, c) = R.at<double>(r, c);
    p.t(r) = tvec.at<double>(r);
  }
  return p;
}

inline geom::Pose poseFromRvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  return poseFromMatrix(R, tvec);
}

}  // namespace procam::calib::detail
