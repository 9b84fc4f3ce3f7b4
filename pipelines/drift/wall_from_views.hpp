#pragma once
// Whether the wall moved, from the content alone, when two fixed cameras watch an
// output: the content drawn at one framebuffer point was found by each camera's drift
// check at a camera pixel (the check's map at where the tile was found); the two rays
// meet on the wall as it stands now, wherever the projector is. With one camera a moved
// wall and a moved projector both move the content by a collineation and cannot be told
// apart; with two, the triangulated points either lie on the rig's plane (the projector
// moved) or off it (the surface moved, [Raskar02] §4.1.1 triangulation from a calibrated
// camera pair). Pure.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"
#include "misregistration.hpp"
#include "projector_camera_map.hpp"

namespace procam::drift {

// One camera's last check of the output: its calibration, the misregistration it
// measured and the map and grid that check used.
struct WallView {
  const geom::CameraModel* camera = nullptr;
  const Misregistration* drift = nullptr;
  const cv::Mat* map = nullptr;  // CV_32FC2 of grid.size()
  WorkGrid grid;
};

struct WallSeen {
  geom::Plane plane;       // fitted to the triangulated content
  double rms_m = 0;        // the points' scatter about it
  int points = 0;          // content points both cameras registered
  double offset_m = 0;     // the points' mean signed distance from the rig's plane
  double offset_se_m = 0;  // its standard error
  double tilt_deg = 0;     // between the fitted plane and the rig's
  double tilt_se_deg = 0;  // the fitted normal's standard error
};

// Rays of the two cameras that pass further apart than this saw different points.
inline constexpr double kMaxRayGapM = 0.005;

// Moved: the points stand off the rig's plane by more than `min_offset_m` and by more
// than six standard errors, or the plane turned by more than `min_tilt_deg` and by more
// than six of its standard errors.
bool wallMoved(const WallSeen& seen, double min_offset_m = 0.002, double min_tilt_deg = 0.3);

// kTooFewPoints under 8 content points both cameras registered (inlier tiles of the same
// framebuffer point whose rays meet within kMaxRayGapM); kInvalidInput for a missing or
// mismatched view; fitPlane's errors.
Result<WallSeen> wallFromTwoViews(const WallView& a, const WallView& b,
                                  const geom::Plane& rig_plane);

}  // namespace procam::drift
