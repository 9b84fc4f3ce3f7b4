#include "calibration/board_plane.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "calibration/opencv_camera.hpp"

namespace procam::calib {
namespace {

// Smallest over largest principal extent of the board points below this: they lie
// on a line, and the board's rotation about it is not observed.
constexpr double kCollinearRatio = 1e-3;

Result<void> checkView(const BoardView& view) {
  if (view.image.size() != view.board.size())
    return fail(ErrorCode::kInvalidInput, "board view: image and board point counts differ");
  if (view.image.size() < 6)
    return fail(ErrorCode::kTooFewPoints, "the board plane needs at least 6 board points, got " +
                                              std::to_string(view.image.size()));
  for (std::size_t i = 0; i < view.image.size(); ++i) {
    if (!view.image[i].allFinite() || !view.board[i].allFinite())
      return fail(ErrorCode::kInvalidInput, "board view: non-finite point");
    if (std::abs(view.board[i].z()) > 1e-9)
      return fail(ErrorCode::kInvalidInput, "board view: board points must lie on z = 0");
  }
  Vec2 mean = Vec2::Zero();
  for (const Vec3& b : view.board) mean += b.head<2>();
  mean /= static_cast<double>(view.board.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const Vec3& b : view.board) cov += (b.head<2>() - mean) * (b.head<2>() - mean).transpose();
  const Vec2 ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvalues();
  if (!(ev.y() > 0) || std::sqrt(std::max(ev.x(), 0.0) / ev.y()) < kCollinearRatio)
    return fail(ErrorCode::kDegenerate, "board points are collinear: no plane");
  return {};
}

}  // namespace

Result<BoardPlane> boardPlane(const geom::CameraModel& camera, const BoardView& view,
                              const BoardPlaneOptions& options) {
  if (auto ok = checkView(view); !ok) return tl::unexpected(ok.error());
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (std::size_t i = 0; i < view.image.size(); ++i) {
    object.emplace_back(view.board[i].x(), view.board[i].y(), 0.0);
    image.emplace_back(view.image[i].x(), view.image[i].y());
  }
  const cv::Mat K = detail::cameraMatrix(camera), dist = detail::distCoeffs(camera);
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(object, image, K, dist, rvec, tvec, false, cv::SOLVEPNP_IPPE))
      return fail(ErrorCode::kNoConvergence, "board pose: PnP found no solution");
    cv::solvePnPRefineLM(object, image, K, dist, rvec, tvec);
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kNoConvergence, std::string("board pose: ") + e.what());
  }
  BoardPlane out;
  out.board_pose = detail::poseFromRvec(rvec, tvec);
  out.points = object.size();
  std::vector<cv::Point2d> reprojected;
  cv::projectPoints(object, rvec, tvec, K, dist, reprojected);
  double sq = 0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const cv::Point2d e = reprojected[i] - image[i];
    sq += e.dot(e);
  }
  out.rms_px = std::sqrt(sq / static_cast<double>(image.size()));
  if (!std::isfinite(out.rms_px) || !out.board_pose.R.allFinite() || !out.board_pose.t.allFinite())
    return fail(ErrorCode::kNoConvergence, "board pose: not finite");
  if (out.rms_px > options.max_rms_px)
    return fail(ErrorCode::kNoConvergence, "board pose: reprojection RMS " +
                                               std::to_string(out.rms_px) + " px exceeds " +
                                               std::to_string(options.max_rms_px) +
                                               " px (a wrong detection or camera calibration?)");
  // The board plane in the camera frame: normal R e3 through the board origin t.
  const Vec3 n_camera = out.board_pose.R.col(2);
  const Vec3 origin_camera = out.board_pose.t;
  const double cos_incidence = std::abs(n_camera.dot(origin_camera.normalized()));
  out.incidence_deg = std::acos(std::min(1.0, cos_incidence)) * 180.0 / std::numbers::pi;
  if (out.incidence_deg > options.max_incidence_deg)
    return fail(ErrorCode::kDegenerate, "board seen " + std::to_string(out.incidence_deg) +
                                            " degrees off its normal: too nearly edge-on");
  // Into the world: x_camera = R x_world + t.
  const geom::Pose& cam = camera.pose;
  const Vec3 n_world = cam.R.transpose() * n_camera;
  const Vec3 origin_world = cam.R.transpose() * (origin_camera - cam.t);
  out.plane = geom::orientedPlane(n_world.normalized(), origin_world);
  return out;
}

}  // namespace procam::calib
