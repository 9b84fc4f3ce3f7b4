#pragma once
// Per-frame pose pipeline shared by every IR LED tracker: blob centres of one
// frame -> constellation pose (keeping the last pose for estimateConstellationPose's
// shortcut) -> optional tracker -> world registration ([Raskar02] eq. 4.2, §4.2.5) -> motion filter
// with prediction by the display latency ([Raskar02] §4.1.4). Pure: no I/O.
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "tracking/constellation_pose.hpp"
#include "tracking/motion_filter.hpp"
#include "tracking/tracker_registration.hpp"

namespace procam::tracking {

struct LedTrackerOptions {
  Points3 leds;  // LED positions in the constellation frame, m (>= 4, not collinear)
  ConstellationOptions pose;
  MotionFilterOptions filter;
  // Maps the camera's frame of reference (camera.pose's "world") to the world; none when
  // the camera pose is already in world coordinates.
  std::optional<TrackerRegistration> to_world;
};

struct TrackedPose {
  Vec3 raw = Vec3::Zero();        // constellation origin from this frame alone, world
  Vec3 filtered = Vec3::Zero();   // after the motion filter, at `time`
  Vec3 predicted = Vec3::Zero();  // filtered + velocity * prediction_s
  Vec3 velocity = Vec3::Zero();   // m/s, world
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // constellation -> world
  Mat3 covariance = Mat3::Zero();  // of `raw`, m^2 (first order, pose.pixel_sigma)
  double rms_px = 0;               // reprojection RMS over the matched LEDs
  int matched = 0;                 // LEDs matched to blobs
  double time = 0;                 // s, the frame's
};

class LedTracker {
 public:
  // kInvalidInput for fewer than 4 LEDs, non-finite LEDs, more LEDs than
  // pose.max_hypotheses allows with 4 blobs, a camera without positive focal lengths or
  // bad filter options.
  static Result<LedTracker> create(const geom::CameraModel& camera,
                                   const LedTrackerOptions& options);

  // Blobs of one frame (camera pixels, distorted, strongest first as detectBlobs gives
  // them) at `time` (s, increasing). When the hypothesis search would exceed
  // pose.max_hypotheses it runs on the strongest searchBlobs() blobs. Errors of
  // estimateConstellationPose pass through (kNotFound / kTooFewPoints when the LEDs are
  // not seen); the filter keeps its state across such frames.
  Result<TrackedPose> update(std::span<const Vec2> blobs, double time);
  // Forgets the previous pose and the filter's state (e.g. after the camera reopens).
  void reset();

  // Most blobs the hypothesis search takes within pose.max_hypotheses.
  size_t searchBlobs() const { return search_blobs_; }
  const geom::CameraModel& camera() const { return camera_; }
  const LedTrackerOptions& options() const { return options_; }

 private:
  LedTracker(const geom::CameraModel& camera, const LedTrackerOptions& options, MotionFilter filter,
             size_t search_blobs)
      : camera_(camera),
        options_(options),
        filter_(std::move(filter)),
        search_blobs_(search_blobs) {}

  geom::CameraModel camera_;
  LedTrackerOptions options_;
  MotionFilter filter_;
  size_t search_blobs_;
  std::optional<geom::Pose> previous_;  // constellation -> camera, last good frame
};

}  // namespace procam::tracking
