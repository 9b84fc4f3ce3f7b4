#include "tracking/led_tracker.hpp"

#include <cmath>

namespace procam::tracking {
namespace {

// The largest blob count whose hypotheses, C(leds, 4) LED quadruples x P(blobs, 4)
// ordered blob quadruples (estimateConstellationPose's search), stay within `budget`;
// 0 when even 4 blobs exceed it.
size_t searchBlobLimit(size_t leds, long budget) {
  const double quads = static_cast<double>(leds) * (leds - 1) * (leds - 2) * (leds - 3) / 24;
  size_t n = 0;
  for (size_t b = 4; b < 4096; ++b) {
    if (quads * static_cast<double>(b) * (b - 1) * (b - 2) * (b - 3) > static_cast<double>(budget))
      break;
    n = b;
  }
  return n;
}

}  // namespace

Result<LedTracker> LedTracker::create(const geom::CameraModel& camera,
                                      const LedTrackerOptions& options) {
  if (options.leds.size() < 4)
    return fail(ErrorCode::kInvalidInput, "LED tracker: at least 4 LEDs are needed");
  for (const Vec3& led : options.leds)
    if (!led.allFinite()) return fail(ErrorCode::kInvalidInput, "LED tracker: non-finite LED");
  if (!(std::isfinite(camera.K.fx) && camera.K.fx > 0 && std::isfinite(camera.K.fy) &&
        camera.K.fy > 0 && std::isfinite(camera.K.cx) && std::isfinite(camera.K.cy)) ||
      !camera.pose.R.allFinite() || !camera.pose.t.allFinite())
    return fail(ErrorCode::kInvalidInput, "LED tracker: camera intrinsics or pose invalid");
  if (options.to_world && !(std::isfinite(options.to_world->scale) && options.to_world->scale > 0))
    return fail(ErrorCode::kInvalidInput, "LED tracker: registration scale must be positive");
  const size_t search_blobs = searchBlobLimit(options.leds.size(), options.pose.max_hypotheses);
  if (search_blobs == 0)
    return fail(ErrorCode::kInvalidInput,
                "LED tracker: " + std::to_string(options.leds.size()) +
                    " LEDs exceed the pose search's max_hypotheses even with 4 blobs");
  auto filter = MotionFilter::create(options.filter);
  if (!filter) return tl::unexpected(filter.error());
  return LedTracker(camera, options, std::move(*filter), search_blobs);
}

void LedTracker::reset() {
  previous_.reset();
  filter_.reset();
}

Result<TrackedPose> LedTracker::update(std::span<const Vec2> blobs, double time) {
  if (!std::isfinite(time)) return fail(ErrorCode::kInvalidInput, "LED tracker: bad frame time");
  auto pose = estimateConstellationPose(camera_, options_.leds, blobs, options_.pose, previous_);
  if (!pose && pose.error().code == ErrorCode::kInvalidInput && blobs.size() > search_blobs_)
    pose = estimateConstellationPose(camera_, options_.leds, blobs.first(search_blobs_),
                                     options_.pose, previous_);
  if (!pose) {
    previous_.reset();  // a stale pose would only cost a failed refinement next frame
    return tl::unexpected(pose.error());
  }
  previous_ = pose->pose;

  // Constellation -> camera-reference frame: R_cam^T R_pose (camera.pose maps world -> camera).
  Mat3 orientation = camera_.pose.R.transpose() * pose->pose.R;
  Vec3 raw = pose->position_world;
  Mat3 cov = pose->covariance_world;
  if (options_.to_world) {
    const TrackerRegistration& reg = *options_.to_world;
    raw = reg.toWorld(raw);
    orientation = reg.tracker_to_world.R * orientation;
    const Mat3 A = reg.scale * reg.tracker_to_world.R;
    cov = A * cov * A.transpose();
  }
  auto filtered = filter_.update(raw, time);
  if (!filtered) return tl::unexpected(filtered.error());

  TrackedPose out;
  out.raw = raw;
  out.filtered = filtered->position;
  out.predicted = filtered->predicted;
  out.velocity = filtered->velocity;
  out.orientation = Eigen::Quaterniond(orientation).normalized();
  out.covariance = cov;
  out.rms_px = pose->rms_px;
  out.matched = pose->matched;
  out.time = time;
  return out;
}

}  // namespace procam::tracking
