#pragma once
// The ir_camera head tracker: an IR-filtered camera, opened through any camera
// driver of the plugin ABI, seeing the LEDs on the viewer's glasses or cap. Per frame:
// blobs (threshold, connected components, sub-pixel centroids) -> tracking::LedTracker
// (constellation pose, tracker -> world registration, motion filter, prediction by the
// display latency, [Raskar02] §4.1.4). Errors are procam::Result with the camera's device
// codes (kAgain for a frame without a pose).
#include <procamd/procam_plugin.h>

#include <optional>

#include "camera/camera.hpp"
#include "tracking/blob_detector.hpp"
#include "tracking/led_tracker.hpp"

namespace procam::tracker {

// A camera device created through the plugin ABI, destroyed with its owner.
class OwnedCamera {
 public:
  OwnedCamera() = default;
  explicit OwnedCamera(const procam_device& device) : device_(device) {}
  OwnedCamera(OwnedCamera&& other) noexcept : device_(other.device_) { other.device_ = {}; }
  OwnedCamera& operator=(OwnedCamera&& other) noexcept;
  OwnedCamera(const OwnedCamera&) = delete;
  OwnedCamera& operator=(const OwnedCamera&) = delete;
  ~OwnedCamera() { release(); }

  bool valid() const { return device_.destroy != nullptr && device_.ops.camera != nullptr; }
  const procam_device& raw() const { return device_; }

 private:
  void release();
  procam_device device_{};
};

struct IrCameraConfig {
  geom::Intrinsics K;     // of the camera's frames (their size comes from the camera)
  geom::Distortion dist;  // OpenCV radial-tangential
  geom::Pose pose;        // tracker frame -> camera (identity: the camera's own frame)
  tracking::BlobOptions blobs;
  tracking::LedTrackerOptions tracker;  // LEDs, pose gates, filter, registration to the world
  int capture_timeout_ms = 0;           // 0: read() never waits (the daemon polls poll_fd)
};

class IrCameraTracker {
 public:
  // kInvalid for a camera delivering rgb8 (IR blobs need gray8 or gray16), bad blob
  // options or what LedTracker::create refuses.
  static Result<IrCameraTracker> create(OwnedCamera camera, const IrCameraConfig& config);

  // One frame: the viewer's predicted world position, the constellation's orientation
  // and the frame's timestamp. Camera errors pass through (PROCAM_ENODEV when it went
  // away, PROCAM_EEND when a recording ended, PROCAM_EAGAIN when no frame is waiting);
  // PROCAM_EAGAIN with a reason when the frame gives no pose ("LEDs not seen: ...").
  Result<procam_pose_sample> read();
  int pollFd() const;

  // The last frame's full result (raw, filtered, predicted), none before the first pose.
  const std::optional<tracking::TrackedPose>& lastPose() const { return last_; }

 private:
  IrCameraTracker(OwnedCamera camera, const IrCameraConfig& config, tracking::LedTracker tracker)
      : camera_(std::move(camera)), config_(config), tracker_(std::move(tracker)) {}

  OwnedCamera camera_;
  IrCameraConfig config_;
  tracking::LedTracker tracker_;
  std::optional<tracking::TrackedPose> last_;
  std::optional<double> last_time_;  // s, of the last frame
};

}  // namespace procam::tracker
