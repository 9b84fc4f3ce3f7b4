#pragma once
// The hid head tracker: a Wii Remote's IR camera watching the 4 IR LEDs on the
// viewer's glasses or cap, its blob frames fed to tracking::LedTracker (constellation
// pose, tracker -> world registration, motion filter, prediction by the display
// latency, [Raskar02] §4.1.4) like the ir_camera tracker's.
#include <procamd/procam_plugin.h>

#include <optional>

#include "tracker/hid/wiimote_ir_source.hpp"
#include "tracking/led_tracker.hpp"

namespace procam::tracker::wiimote {

class WiimoteTracker {
 public:
  // `camera`: the IR camera's model (wiimoteCamera() unless calibrated) and its pose in
  // the tracker frame. What LedTracker::create refuses passes through.
  static Result<WiimoteTracker> create(WiimoteIrSource source, const geom::CameraModel& camera,
                                       const tracking::LedTrackerOptions& options);

  // One data report: the pose of its blobs. kNotFound when no report is waiting within
  // the timeout; LedTracker's kNotFound / kTooFewPoints when the LEDs are not seen
  // (their count in the message); the source's errors pass through.
  Result<tracking::TrackedPose> read(int timeout_ms);
  // The same as the ABI's sample: predicted position, orientation, timestamp.
  static procam_pose_sample sample(const tracking::TrackedPose& pose, std::uint64_t timestamp_ns);

  int pollFd() const { return source_.pollFd(); }
  const std::optional<tracking::TrackedPose>& lastPose() const { return last_; }
  std::uint64_t lastTimestampNs() const { return last_ns_; }

 private:
  WiimoteTracker(WiimoteIrSource source, tracking::LedTracker tracker)
      : source_(std::move(source)), tracker_(std::move(tracker)) {}

  WiimoteIrSource source_;
  tracking::LedTracker tracker_;
  std::optional<tracking::TrackedPose> last_;
  std::optional<std::uint64_t> last_frame_ns_;
  std::uint64_t last_ns_ = 0;
};

}  // namespace procam::tracker::wiimote
