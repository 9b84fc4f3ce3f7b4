#pragma once
// `calibrate-camera` (PROTOCOL.md): a camera's intrinsics from a board the installer
// moves in front of it ([Zhang99], [Raskar02] §4.1.1 step one). The worker captures a
// frame every `interval_s`, detects the board, keeps the views that add something
// (calib::BoardViewSet), re-solves after every kept view for the running reprojection
// RMS, and stops when the views, the image coverage and the RMS reach their targets,
// when asked to finish (with the views it has), at the time limit, or when cancelled.
#include <atomic>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <tl/expected.hpp>

#include "calibration/board.hpp"
#include "calibration/camera_calibration.hpp"
#include "calibration_job.hpp"

namespace procam::daemon {

struct CameraCalibrationArgs {
  std::string camera;  // empty: the first usable camera
  calib::BoardSpec board;
  std::string board_text;
  int views = 15;           // kept views to reach
  double coverage = 0.6;    // share of the image the kept views cover, to reach
  double rms_px = 0.5;      // reprojection RMS to get under
  double timeout_s = 600;   // the longest a run takes; then it solves with what it has
  double interval_s = 0.3;  // between two captures
  double min_shift = 0.03;  // a view repeats a kept one below this mean shift (of the diagonal)
};

// The message names the offending key.
tl::expected<CameraCalibrationArgs, std::string> parseCameraCalibrationArgs(
    const nlohmann::json& request);

struct CameraCalibrationPlan {
  CalibrationDevice camera;
  CameraCalibrationArgs args;
  int width = 0, height = 0;
  std::shared_ptr<std::atomic<bool>> finish;  // set: solve with the views kept so far
};

// What the installer sees after every frame.
struct CameraCalibrationStatus {
  int frames = 0;                       // captured
  int kept = 0;                         // views kept
  std::map<std::string, int> rejected;  // frames not kept, by reason
  double coverage = 0;
  double rms_px = -1;  // < 0 until a solve succeeded
  std::string last;    // what became of the last frame
};
nlohmann::json cameraCalibrationJson(const CameraCalibrationStatus& status);

struct CameraCalibrationResult {
  calib::CameraCalibration calibration;
  CameraCalibrationStatus status;
  std::string stopped;  // "targets", "views" (twice the views asked), "finish" or "timeout"
};

// kFailed with the counts when fewer than 4 views were kept.
tl::expected<CameraCalibrationResult, CalibrationFailure> runCameraCalibration(
    const CameraCalibrationPlan& plan, const CalibrationHooks& hooks,
    const std::function<void(const CameraCalibrationStatus&)>& on_frame);

}  // namespace procam::daemon
