#include "projector_camera_map.hpp"

#include <cmath>

namespace procam::drift {

Result<cv::Mat> projectorCameraMap(const geom::PlaneHomography& projector_to_plane,
                                   const geom::CameraModel& camera, const WorkGrid& grid) {
  if (grid.factor < 1 || grid.factor > 8 || grid.size().width < 1 || grid.size().height < 1) {
    return fail(ErrorCode::kInvalidInput,
                "drift map: a framebuffer of at least the sampling "
                "factor (1 to 8) on each side is needed");
  }
  if (!projector_to_plane.H.allFinite() || !camera.pose.R.allFinite() ||
      !camera.pose.t.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "drift map: the rig model's mapping is not finite");
  }
  const cv::Size size = grid.size();
  cv::Mat map(size, CV_32FC2, cv::Scalar(-1, -1));
  const Mat3& H = projector_to_plane.H;
  // Pixels whose rays miss the plane map to points behind the projector: the
  // homogeneous scale changes sign from the frame's centre (which lights the plane).
  const Vec2 centre = grid.toFramebuffer({size.width / 2.0, size.height / 2.0});
  const double lit_sign = (H * Vec3(centre.x(), centre.y(), 1.0)).z() >= 0 ? 1.0 : -1.0;
  for (int y = 0; y < size.height; ++y) {
    auto* row = map.ptr<cv::Vec2f>(y);
    for (int x = 0; x < size.width; ++x) {
      const Vec2 fb = grid.toFramebuffer({x, y});
      const Vec3 ab = H * Vec3(fb.x(), fb.y(), 1.0);
      if (!(ab.z() * lit_sign > 1e-12)) continue;  // at or past the plane's horizon
      const Vec3 world = projector_to_plane.basis.toWorld({ab.x() / ab.z(), ab.y() / ab.z()});
      const auto px = camera.project(world);
      // Inside the outermost pixel centres: resampling there reads no pixel off the image.
      if (!px || !(px->x() >= 0 && px->y() >= 0 && px->x() <= camera.width - 1 &&
                   px->y() <= camera.height - 1)) {
        continue;
      }
      row[x] = cv::Vec2f(static_cast<float>(px->x()), static_cast<float>(px->y()));
    }
  }
  return map;
}

std::optional<Vec2> mappedCameraPixel(const cv::Mat& map, const Vec2& w) {
  const int x0 = static_cast<int>(std::floor(w.x())), y0 = static_cast<int>(std::floor(w.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= map.cols || y0 + 1 >= map.rows) return std::nullopt;
  const double fx = w.x() - x0, fy = w.y() - y0;
  Vec2 sum = Vec2::Zero();
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const cv::Vec2f c = map.at<cv::Vec2f>(y0 + dy, x0 + dx);
      if (c[0] < 0) return std::nullopt;
      sum += (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * Vec2(c[0], c[1]);
    }
  }
  return sum;
}

}  // namespace procam::drift
