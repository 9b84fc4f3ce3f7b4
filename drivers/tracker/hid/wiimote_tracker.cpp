#include "tracker/hid/wiimote_tracker.hpp"

#include <algorithm>
#include <string>

namespace procam::tracker::wiimote {

Result<WiimoteTracker> WiimoteTracker::create(WiimoteIrSource source,
                                              const geom::CameraModel& camera,
                                              const tracking::LedTrackerOptions& options) {
  auto tracker = tracking::LedTracker::create(camera, options);
  if (!tracker) return fail(tracker.error().code, "wiimote tracker: " + tracker.error().message);
  return WiimoteTracker(std::move(source), std::move(*tracker));
}

Result<tracking::TrackedPose> WiimoteTracker::read(int timeout_ms) {
  auto frame = source_.read(timeout_ms);
  if (!frame) return tl::unexpected(frame.error());
  // A clock that went back (a replay starting over) starts a new track.
  if (last_frame_ns_ && frame->timestamp_ns <= *last_frame_ns_) tracker_.reset();
  last_frame_ns_ = frame->timestamp_ns;
  // Strongest first, as LedTracker takes them: the size is the camera's blob weight.
  std::vector<IrBlob> blobs = frame->blobs;
  std::stable_sort(blobs.begin(), blobs.end(),
                   [](const IrBlob& a, const IrBlob& b) { return a.size > b.size; });
  Points2 centres;
  for (const IrBlob& b : blobs) centres.push_back(b.pixel);
  auto pose = tracker_.update(centres, double(frame->timestamp_ns) * 1e-9);
  if (!pose)
    return fail(pose.error().code, "LEDs not seen: " + std::to_string(centres.size()) +
                                       " blob(s), " + pose.error().message);
  last_ = *pose;
  last_ns_ = frame->timestamp_ns;
  return *pose;
}

procam_pose_sample WiimoteTracker::sample(const tracking::TrackedPose& pose,
                                          std::uint64_t timestamp_ns) {
  procam_pose_sample s{};
  for (int i = 0; i < 3; ++i) s.position[i] = pose.predicted(i);
  s.orientation[0] = pose.orientation.w();
  s.orientation[1] = pose.orientation.x();
  s.orientation[2] = pose.orientation.y();
  s.orientation[3] = pose.orientation.z();
  s.timestamp_ns = timestamp_ns;
  return s;
}

}  // namespace procam::tracker::wiimote
