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
#include "rig/rig_model.hpp"

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
  geom::Plane plane;    // fitted to the triangulated content
  geom::Plane shifted;  // the rig's plane moved by offset_m along its normal
  double rms_m = 0;     // the points' scatter about it
  int points = 0;       // content points whose rays met
  int rays = 0;         // content points tried (registered in both views)
  // One camera: the RMS distance between the projector's and the camera's rays, and the
  // content's RMS shift on the rig's plane (where the camera sees it against where the
  // rig puts it).
  double gap_rms_m = 0, shift_rms_m = 0;
  // wallFromOneCamera: how far the projector would have turned had it moved instead.
  double projector_turn_deg = 0;
  // A turn under this is not kept (wallTurned); wallFromOneCamera sets it.
  double tilt_floor_deg = 0;
  double offset_m = 0;     // the points' mean signed distance from the rig's plane
  double offset_se_m = 0;  // its standard error
  double tilt_deg = 0;     // between the fitted plane and the rig's
  double tilt_se_deg = 0;  // the fitted normal's standard error
};

// Rays of the two views that pass further apart than this saw different points.
inline constexpr double kMaxRayGapM = 0.005;

// Moved: the points stand off the rig's plane by more than `min_offset_m` and by more
// than six standard errors, or the plane turned by more than `min_tilt_deg` and by more
// than six of its standard errors.
bool wallMoved(const WallSeen& seen, double min_offset_m = 0.002, double min_tilt_deg = 0.3);

// Whether the fitted plane turned from the rig's by more than six of its standard errors
// and more than seen.tilt_floor_deg.
bool wallTurned(const WallSeen& seen);

// The wall to keep: the fitted plane when it turned (wallTurned), else the rig's plane
// shifted by the points' mean distance from it.
geom::Plane wallToKeep(const WallSeen& seen);

// One camera's points tilt the plane beyond what their scatter says (their errors share
// the one view's geometry): 0.0178 deg, 7 of its standard errors, for the wall moved
// 1 cm on wall_oblique, which moves the content 0.37 projector px at the wall's far
// edge. A turn under this is not kept from one camera.
inline constexpr double kOneCameraTiltFloorDeg = 0.1;

// kTooFewPoints under 8 content points both cameras registered (inlier tiles of the same
// framebuffer point whose rays meet within kMaxRayGapM); kInvalidInput for a missing or
// mismatched view; fitPlane's errors.
Result<WallSeen> wallFromTwoViews(const WallView& a, const WallView& b,
                                  const geom::Plane& rig_plane);

// For the projector and the camera to stand where the rig has them, the share of a
// one-camera wall's rays that must meet, and the largest RMS distance between the rays
// as a share of the content's RMS shift on the wall: a moved wall shifts the content
// along the epipolar lines (the rays meet, to the measurement's noise), a turned
// projector shifts it across them too (on wall_oblique 0.5 deg puts no ray within
// 5 mm), however small the turn.
inline constexpr double kMinMetShare = 0.8;
inline constexpr double kMaxGapShare = 0.15;

// `projector`: the rig's projector model (pose, intrinsics, distortion); `camera`: the
// one camera's last check. kTooFewPoints under 8 content points whose rays met, under
// kMinMetShare of the registered ones, or rays further apart than kMaxGapShare of the
// shift (the projector or the camera moved, or the content moved too little to tell);
// as wallFromTwoViews otherwise.
Result<WallSeen> wallFromProjectorAndView(const geom::CameraModel& projector,
                                          const WallView& camera, const geom::Plane& rig_plane);

// A moved wall changes the content's collineation as a projector sliding along the
// baseline would, without turning: had the projector moved instead, the pose fitted to
// the content (drift/projector_correction.hpp) turns by less than this (a wall moved 1 cm
// on wall_oblique fits as under 0.004 deg; a turn of 0.05 deg as 0.0505 deg). A turn
// along the epipolar lines keeps the rays meeting and needs this test: a bump of 0.3 deg
// about two axes on wall_oblique triangulates as a wall 96 mm away.
inline constexpr double kMaxWallProjectorTurnDeg = 0.02;

// The wall from one camera and the rig's projector (pose, intrinsics, distortion known):
// wallFromProjectorAndView's result and errors, and kDegenerate when the pose fitted to
// the content turns the projector by more than kMaxWallProjectorTurnDeg (the projector
// moved) or cannot be fitted. `tile`: the collineation the drift check's map used.
Result<WallSeen> wallFromOneCamera(const rig::RigProjector& projector,
                                   const geom::PlaneHomography& tile, const WallView& camera,
                                   const geom::Plane& rig_plane);

}  // namespace procam::drift
