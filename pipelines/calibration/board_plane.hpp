#pragma once
// The display plane from a calibration board fixed flat on it and seen by one
// calibrated camera: route (b′) ([Raskar02] §4.2.4) maps the projector onto the
// display plane through the camera, and a board of known dimensions tells where that
// plane is. The board's pose comes from planar PnP (IPPE, then Levenberg–Marquardt on
// the reprojection error, OpenCV calib3d) with the camera's K and distortion; its
// plane is carried into the world by the camera's pose.
#include <cstddef>

#include "calibration/board.hpp"
#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"

namespace procam::calib {

struct BoardPlane {
  geom::Plane plane;         // world; oriented as geom::orientedPlane
  geom::Pose board_pose;     // board frame (z = 0 on the board) -> camera
  double rms_px = 0;         // reprojection RMS of the board points
  std::size_t points = 0;    // board points used
  double incidence_deg = 0;  // between the camera's ray to the board and its normal
};

struct BoardPlaneOptions {
  double max_rms_px = 2.0;          // above: a wrong detection or camera model
  double max_incidence_deg = 80.0;  // above: the board is seen too nearly edge-on
};

// kInvalidInput for mismatched sizes, non-finite values or board points off z = 0;
// kTooFewPoints below 6 points; kDegenerate when the board points are (nearly)
// collinear or the board is seen beyond max_incidence_deg; kNoConvergence when PnP
// fails or its RMS exceeds max_rms_px.
Result<BoardPlane> boardPlane(const geom::CameraModel& camera, const BoardView& view,
                              const BoardPlaneOptions& options = {});

}  // namespace procam::calib
