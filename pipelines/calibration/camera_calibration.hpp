#pragma once
// Camera intrinsics from board views (cv::calibrateCamera, Zhang's method) and the
// extrinsics of a camera pair from simultaneous views ([Raskar02] §4.1.1 step one,
// "Camera Calibration").
#include <span>
#include <vector>

#include "calibration/board.hpp"
#include "core/error.hpp"
#include "geometry/camera_model.hpp"

namespace procam::calib {

struct CameraCalibrationOptions {
  bool fix_k3 = true;  // k3 is rarely observable from a handful of views
  bool zero_tangential = false;
};

struct CameraCalibration {
  geom::CameraModel camera;             // pose: identity (camera frame = world)
  double rms_px = 0;                    // reprojection RMS over all corners
  std::vector<geom::Pose> board_poses;  // board -> camera, one per view
};

// kTooFewPoints below 3 views or 6 points in a view; kNoConvergence when OpenCV fails.
Result<CameraCalibration> calibrateCamera(std::span<const BoardView> views, int width, int height,
                                          const CameraCalibrationOptions& options = {});

struct StereoCalibration {
  geom::Pose b_from_a;  // x_b = R x_a + t
  double rms_px = 0;
};

// Intrinsics fixed; views_a[i] and views_b[i] show the same board pose and the same
// board points in the same order (as detectBoard returns for full checkerboards).
Result<StereoCalibration> calibrateStereo(const geom::CameraModel& a,
                                          std::span<const BoardView> views_a,
                                          const geom::CameraModel& b,
                                          std::span<const BoardView> views_b);

}  // namespace procam::calib
