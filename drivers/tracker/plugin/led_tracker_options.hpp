#pragma once
// Options every IR LED tracker driver shares (ir_camera, and the Wii Remote's hid driver):
// the tracking camera's intrinsics and pose, the LED layout, the pose gates, the motion
// filter and the tracker -> world registration. README.md lists them with their defaults.
#include <string>

#include "geometry/camera_model.hpp"
#include "support/driver_support.hpp"
#include "tracking/led_tracker.hpp"

namespace procam::tracker::plugin {

// Keys of trackerCamera() and ledTrackerOptions(), for DriverOptions::onlyKnown().
#define PROCAM_TRACKER_CAMERA_KEYS                                                        \
  "fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "camera_position", "camera_rvec", \
      "camera_look_at", "camera_up"
#define PROCAM_LED_TRACKER_KEYS                                                                    \
  "leds", "max_reprojection_px", "pixel_sigma", "min_leds", "filter", "min_cutoff_hz", "beta",     \
      "derivative_cutoff_hz", "accel_noise", "measurement_sigma", "prediction_s", "to_world_rvec", \
      "to_world_t", "to_world_scale"

// "x,y,z" -> Vec3; "x,y,z;x,y,z;..." -> points. kInvalidInput naming the option.
Result<Vec3> vec3Option(const plugins::DriverOptions& o, const char* key, const std::string& text);
Result<Points3> pointsOption(const plugins::DriverOptions& o, const char* key,
                             const std::string& text);

// The camera's intrinsics (fx, fy, cx, cy required; k1 k2 p1 p2 k3 optional) and its pose
// in the tracker frame: camera_position (its centre, default the origin) and either
// camera_rvec (OpenCV rotation vector, tracker frame -> camera, as a calibration reports
// it) or camera_look_at with camera_up (default 0,0,1: the world's up, ARCHITECTURE.md).
// Width and height are left 0 (the camera's frames decide).
Result<geom::CameraModel> trackerCamera(const plugins::DriverOptions& o);

// LEDs (required, >= 4), pose gates, filter (one_euro / kalman), prediction_s and the
// optional registration to the world (to_world_rvec, to_world_t, to_world_scale).
Result<tracking::LedTrackerOptions> ledTrackerOptions(const plugins::DriverOptions& o);

}  // namespace procam::tracker::plugin
