#pragma once
// The calibrate operation's work, apart from the daemon: its arguments, and the
// run on a worker thread that shows every structured-light frame on the output,
// waits for it to settle, captures it with both cameras, decodes and solves route
// (a) (seed §4.1.1) through calib::solveStereoRoute, the pipeline procam-calibrate
// uses on files.
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calibration/stereo_route.hpp"
#include "driver.hpp"
#include "geometry/camera_model.hpp"
#include "structured_light/pattern_set.hpp"
#include "tl/expected.hpp"

namespace procam::daemon {

// The calibrate request's arguments (PROTOCOL.md).
struct CalibrationArgs {
  sl::Mode mode = sl::Mode::kGrayPhase;
  int step = 1;  // one code per `step` projector pixels
  int phase_steps = 8;
  int grid = 8;                      // projector pixels between solved nodes
  int settle_frames = 2;             // output frames to wait after showing a pattern
  std::string output;                // empty: the first usable output
  std::vector<std::string> cameras;  // empty: the first two usable cameras
};

// The message names the offending key.
tl::expected<CalibrationArgs, std::string> parseCalibrationArgs(const nlohmann::json& request);

// A device the run uses; the shared reference keeps it alive if the daemon
// closes its entry meanwhile.
struct CalibrationDevice {
  std::string name;
  std::shared_ptr<plugins::Device> device;
};

struct CalibrationCamera {
  CalibrationDevice device;
  geom::CameraModel model;  // K, distortion, pose (world -> camera)
};

struct CalibrationPlan {
  sl::PatternSet set;
  int grid = 8;
  int settle_frames = 2;
  double refresh_hz = 60;
  CalibrationDevice output;
  std::vector<CalibrationCamera> cameras;  // two: route (a)

  int captures() const { return static_cast<int>(set.frames.size() * cameras.size()); }
};

struct CalibrationProgress {
  double fraction = 0;  // 0..1 over the whole run
  std::string stage;    // "capturing", "decoding", "solving"
  int capture = 0;      // captures done (of plan.captures())
};

struct CalibrationHooks {
  std::function<bool()> cancelled;                           // polled between frames
  std::function<void(const CalibrationProgress&)> progress;  // from the worker thread
};

struct CalibrationFailure {
  const char* code;  // proto::code
  std::string message;
  std::string device = {};  // the device that failed, if one did
  int rc = 0;               // its PROCAM_E* code
};

struct CalibrationOutcome {
  calib::StereoRouteResult route;
  std::vector<int> decoded;  // camera pixels decoded, per camera
};

// Runs on a worker: blocks on the devices; never touches daemon state.
tl::expected<CalibrationOutcome, CalibrationFailure> runCalibration(const CalibrationPlan& plan,
                                                                    const CalibrationHooks& hooks);

}  // namespace procam::daemon
