#pragma once
// Renders a calibration board as a camera with lens distortion sees it: every camera
// pixel is undistorted, cast onto the board plane and looked up in a high-resolution
// board image; 2x supersampling, a slight blur and read noise.
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "calibration/board.hpp"
#include "geometry/camera_model.hpp"

namespace procam::testing {

struct BoardImage {
  cv::Mat pixels;  // CV_8UC1
  double px_per_m = 0;
  Vec2 origin_px;  // board point (0, 0) in pixel-centre coordinates of `pixels`
};

// Normalised (undistorted) ray of every 2x-supersampled camera pixel.
inline std::vector<cv::Point2f> cameraRays(const geom::CameraModel& cam) {
  const int W = 2 * cam.width, H = 2 * cam.height;
  std::vector<cv::Point2f> distorted;
  distorted.reserve(static_cast<std::size_t>(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)  // hi-res pixel centre in camera pixel coordinates
      distorted.emplace_back((x + 0.5f) / 2 - 0.5f, (y + 0.5f) / 2 - 0.5f);
  const cv::Matx33d K(cam.K.fx, cam.K.skew, cam.K.cx, 0, cam.K.fy, cam.K.cy, 0, 0, 1);
  const cv::Matx<double, 1, 5> dist(cam.dist.k1, cam.dist.k2, cam.dist.p1, cam.dist.p2,
                                    cam.dist.k3);
  std::vector<cv::Point2f> normalised;
  cv::undistortPoints(distorted, normalised, K, dist, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 1e-9));
  return normalised;
}

// `board_to_camera` maps board metres (z = 0) into the camera frame; `rays` from
// cameraRays(cam).
inline cv::Mat viewBoard(const BoardImage& board, const geom::CameraModel& cam,
                         const std::vector<cv::Point2f>& normalised,
                         const geom::Pose& board_to_camera, double noise_dn, unsigned seed) {
  const int W = 2 * cam.width, H = 2 * cam.height;
  const Mat3& R = board_to_camera.R;
  const Vec3& t = board_to_camera.t;
  // Ray d = (x, y, 1); board point B with R B + t = s d, B.z = 0.
  const Mat3 Rt = R.transpose();
  cv::Mat map_x(H, W, CV_32F), map_y(H, W, CV_32F);
  for (int i = 0; i < W * H; ++i) {
    const Vec3 d(normalised[i].x, normalised[i].y, 1.0);
    const Vec3 o = -Rt * t, dir = Rt * d;  // camera centre and ray in board frame
    const double s = -o.z() / dir.z();
    const Vec3 b = o + s * dir;
    const bool ok = s > 0 && std::isfinite(s);
    map_x.at<float>(i / W, i % W) =
        ok ? static_cast<float>(board.origin_px.x() + b.x() * board.px_per_m) : -1e5f;
    map_y.at<float>(i / W, i % W) =
        ok ? static_cast<float>(board.origin_px.y() + b.y() * board.px_per_m) : -1e5f;
  }
  cv::Mat hi, out;
  cv::remap(board.pixels, hi, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 128);
  cv::resize(hi, out, cv::Size(cam.width, cam.height), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(out, out, cv::Size(), 0.6);
  cv::Mat noisy(out.size(), CV_16S);
  cv::RNG rng(seed);
  rng.fill(noisy, cv::RNG::NORMAL, 0, noise_dn);
  cv::Mat result;
  out.convertTo(result, CV_16S);
  result += noisy;
  result.convertTo(result, CV_8U);
  return result;
}

// Poses of a board of size (bw, bh) metres, varied in distance and tilt, all centred
// in front of the camera.
inline std::vector<geom::Pose> boardPoses(double bw, double bh, int count) {
  std::vector<geom::Pose> poses;
  for (int i = 0; i < count; ++i) {
    const double ax = 0.45 * std::sin(1.7 * i + 0.3), ay = 0.45 * std::cos(2.3 * i + 0.1);
    const double az = 0.3 * std::sin(0.9 * i);
    geom::Pose p;
    p.R = (Eigen::AngleAxisd(az, Vec3::UnitZ()) * Eigen::AngleAxisd(ax, Vec3::UnitX()) *
           Eigen::AngleAxisd(ay, Vec3::UnitY()))
              .toRotationMatrix();
    const double dist = 0.55 + 0.1 * std::sin(1.3 * i);
    // Board centre at (0.04 sin, 0.03 cos, dist) in the camera frame.
    const Vec3 centre(0.04 * std::sin(2.1 * i), 0.03 * std::cos(1.1 * i), dist);
    p.t = centre - p.R * Vec3(bw / 2, bh / 2, 0);
    poses.push_back(p);
  }
  return poses;
}

}  // namespace procam::testing
