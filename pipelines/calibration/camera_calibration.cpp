#include "calibration/camera_calibration.hpp"

#include <cmath>
#include <opencv2/calib3d.hpp>

#include "calibration/opencv_camera.hpp"

namespace procam::calib {
namespace {

using detail::cameraMatrix;
using detail::distCoeffs;
using detail::poseFromMatrix;
using detail::poseFromRvec;
using ObjectPoints = std::vector<std::vector<cv::Point3f>>;
using ImagePoints = std::vector<std::vector<cv::Point2f>>;

void toCv(const BoardView& v, ObjectPoints& object, ImagePoints& image) {
  object.emplace_back();
  image.emplace_back();
  for (std::size_t i = 0; i < v.board.size(); ++i) {
    object.back().emplace_back(static_cast<float>(v.board[i].x()),
                               static_cast<float>(v.board[i].y()),
                               static_cast<float>(v.board[i].z()));
    image.back().emplace_back(static_cast<float>(v.image[i].x()),
                              static_cast<float>(v.image[i].y()));
  }
}

Result<void> checkViews(std::span<const BoardView> views) {
  if (views.size() < 3)
    return fail(ErrorCode::kTooFewPoints, "camera calibration needs at least 3 board views");
  for (const BoardView& v : views)
    if (v.image.size() < 6 || v.image.size() != v.board.size())
      return fail(ErrorCode::kTooFewPoints, "every board view needs at least 6 matched points");
  return {};
}

}  // namespace

Result<CameraCalibration> calibrateCamera(std::span<const BoardView> views, int width, int height,
                                          const CameraCalibrationOptions& o) {
  if (auto ok = checkViews(views); !ok) return tl::unexpected(ok.error());
  if (width < 1 || height < 1)
    return fail(ErrorCode::kInvalidInput, "camera size must be positive");
  ObjectPoints object;
  ImagePoints image;
  for (const BoardView& v : views) toCv(v, object, image);
  cv::Mat K, dist;
  std::vector<cv::Mat> rvecs, tvecs;
  int flags = 0;
  if (o.fix_k3) flags |= cv::CALIB_FIX_K3;
  if (o.zero_tangential) flags |= cv::CALIB_ZERO_TANGENT_DIST;
  double rms = 0;
  try {
    rms = cv::calibrateCamera(object, image, cv::Size(width, height), K, dist, rvecs, tvecs, flags);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kNoConvergence, std::string("cv::calibrateCamera: ") + e.what());
  }
  if (!std::isfinite(rms) || !cv::checkRange(K) || !cv::checkRange(dist))
    return fail(ErrorCode::kNoConvergence,
                "camera calibration did not converge (views too similar?)");
  CameraCalibration out;
  out.camera.width = width;
  out.camera.height = height;
  out.camera.K = {K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2),
                  K.at<double>(0, 1)};
  const double* d = dist.ptr<double>(0);
  out.camera.dist = {d[0], d[1], d[2], d[3], dist.total() > 4 ? d[4] : 0.0};
  out.rms_px = rms;
  for (std::size_t i = 0; i < rvecs.size(); ++i)
    out.board_poses.push_back(poseFromRvec(rvecs[i], tvecs[i]));
  return out;
}

Result<StereoCalibration> calibrateStereo(const geom::CameraModel& a,
                                          std::span<const BoardView> views_a,
                                          const geom::CameraModel& b,
                                          std::span<const BoardView> views_b) {
  if (auto ok = checkViews(views_a); !ok) return tl::unexpected(ok.error());
  if (views_a.size() != views_b.size())
    return fail(ErrorCode::kInvalidInput, "stereo calibration: both cameras need the same views");
  ObjectPoints object, object_b;
  ImagePoints image_a, image_b;
  for (std::size_t i = 0; i < views_a.size(); ++i) {
    if (views_a[i].board != views_b[i].board)
      return fail(ErrorCode::kInvalidInput,
                  "stereo calibration: view " + std::to_string(i) +
                      " does not show the same board points in both cameras");
    toCv(views_a[i], object, image_a);
    toCv(views_b[i], object_b, image_b);
  }
  cv::Mat Ka = cameraMatrix(a), Kb = cameraMatrix(b), da = distCoeffs(a), db = distCoeffs(b);
  cv::Mat R, T, E, F;
  double rms = 0;
  try {
    rms = cv::stereoCalibrate(object, image_a, image_b, Ka, da, Kb, db, cv::Size(a.width, a.height),
                              R, T, E, F, cv::CALIB_FIX_INTRINSIC);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kNoConvergence, std::string("cv::stereoCalibrate: ") + e.what());
  }
  if (!std::isfinite(rms))
    return fail(ErrorCode::kNoConvergence, "stereo calibration did not converge");
  StereoCalibration out;
  out.b_from_a = poseFromMatrix(R, T);
  out.rms_px = rms;
  return out;
}

}  // namespace procam::calib
