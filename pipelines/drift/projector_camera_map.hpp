#pragma once
// Where a projector's framebuffer pixels land in a camera, by the rig model: the
// projector's collineation with the display plane ([Raskar02] §4.2.1), or its pixel rays
// meeting a surface the rig knows as a mesh (§4.1), and the camera's calibration. The
// drift check compares what the camera sees there with the frame shown.
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>

#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/intersect.hpp"
#include "geometry/plane_homography.hpp"

namespace procam::drift {

// The framebuffer sampled every `factor` pixels: work pixel (x, y) is framebuffer pixel
// (factor x + (factor - 1) / 2, factor y + (factor - 1) / 2), pixel centres on integers.
struct WorkGrid {
  cv::Size framebuffer;
  int factor = 2;

  cv::Size size() const { return {framebuffer.width / factor, framebuffer.height / factor}; }
  double offset() const { return (factor - 1) / 2.0; }
  Vec2 toFramebuffer(const Vec2& work) const {
    return {factor * work.x() + offset(), factor * work.y() + offset()};
  }
  Vec2 toWork(const Vec2& fb) const {
    return {(fb.x() - offset()) / factor, (fb.y() - offset()) / factor};
  }
};

// Where the rig model says a projector's framebuffer pixels light the display surface.
struct LitSurface {
  // The world point a framebuffer pixel lights; nullopt where its light meets no surface.
  std::function<std::optional<Vec3>(const Vec2&)> point;
  // The surface, when it may hide a lit point from a camera (a mesh); null for a plane.
  std::shared_ptr<const geom::MeshIntersector> occluder;
  // The pinhole pixel a framebuffer pixel shows, when the frames are drawn through a
  // post-rendering warp ([Raskar02] §4.1.3) that stands for the projector's lens; empty:
  // the projector's own model has the lens.
  std::function<Vec2(const Vec2&)> to_pinhole;
};

// A display plane's: the collineation, pixels past the plane's horizon lighting nothing.
LitSurface planeLitSurface(const geom::PlaneHomography& projector_to_plane, cv::Size framebuffer);

// For every work pixel, the camera pixel that sees it (CV_32FC2), or (-1, -1) where the
// camera does not (behind it, outside its image, the plane seen edge-on, hidden by another
// part of the surface). kInvalidInput for a factor outside 1..8, an empty framebuffer, no
// surface or a non-finite mapping.
Result<cv::Mat> projectorCameraMap(const LitSurface& surface, const geom::CameraModel& camera,
                                   const WorkGrid& grid);
// The plane's (planeLitSurface).
Result<cv::Mat> projectorCameraMap(const geom::PlaneHomography& projector_to_plane,
                                   const geom::CameraModel& camera, const WorkGrid& grid);

// The map's camera pixel at a work-grid point (bilinear); nullopt off the camera's view.
std::optional<Vec2> mappedCameraPixel(const cv::Mat& map, const Vec2& work);

// The work pixel the map puts at camera pixel `camera`: Newton steps on the map's bilinear
// interpolation from `start`; nullopt where they leave the part of the grid the camera sees
// or do not come within 1e-3 camera px of it.
std::optional<Vec2> workPixelSeenAt(const cv::Mat& map, const Vec2& camera, const Vec2& start);

}  // namespace procam::drift
