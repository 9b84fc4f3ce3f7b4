#pragma once
// The wall seen by the camera mounted on a handheld projector, for the yaw a tilt sensor
// cannot give ([Raskar02] §6.2.2: the rigid camera gives the azimuth). On a worker: the
// projector shows a dot grid, the camera's frames of it are averaged and the wall's
// plane fitted in the projector frame (keystone/dot_grid.hpp). Never touches daemon
// state; the outputs' own frames must be held back meanwhile.
#include <atomic>
#include <memory>
#include <tl/expected.hpp>

#include "calibration_job.hpp"
#include "keystone/dot_grid.hpp"

namespace procam::daemon {

struct WallSightPlan {
  CalibrationDevice output, camera;
  std::shared_ptr<const keystone::DotGrid> grid;  // of the output's framebuffer size
  geom::Intrinsics projector;
  geom::CameraModel camera_in_projector;  // pose: camera from projector
  int frames = 64;                        // camera frames averaged
  double settle_s = 0.05;                 // waited after showing the grid
  // Set when the projector moves, auto keystone is turned off or the daemon stops: the
  // run stops before its next frame. (A calibration queues behind it on the same worker.)
  std::shared_ptr<std::atomic<bool>> stop;
};

struct WallSight {
  keystone::WallFromDots wall;
  int frames = 0;
  double seconds = 0;  // from showing the grid to the last frame
};

// kCancelled-like failure ("stopped") when `stop` was set; the devices' failures; the
// fit's (too few dots seen) as kFailed with its message.
tl::expected<WallSight, CalibrationFailure> measureWallSight(const WallSightPlan& plan);

}  // namespace procam::daemon
