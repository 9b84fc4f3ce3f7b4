#pragma once
// Tracker -> world registration ([Raskar02] eq. 4.2 and §4.2.5): from >= 4 points
// measured by the tracker whose world coordinates are known, or from tracker readings
// of points on a screen that itself defines the world frame (plane z = 0).
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::tracking {

struct TrackerRegistration {
  geom::Pose tracker_to_world;  // x_world = s R x_tracker + t (R, t here; s below)
  double scale = 1;             // 1 unless a similarity was asked for
  double rms = 0;               // m, residual of the measured points
  Vec3 toWorld(const Vec3& tracker) const {
    return scale * tracker_to_world.R * tracker + tracker_to_world.t;
  }
};

// Least-squares rigid (or similarity) fit, eq. 4.2. kTooFewPoints for < 4 pairs or
// unequal counts; kDegenerate for coincident or collinear points.
Result<TrackerRegistration> registerTracker(std::span<const Vec3> tracker,
                                            std::span<const Vec3> world, bool with_scale = false);

// §4.2.5: tracker readings of >= 4 points on the screen; world origin at
// `tracker[origin]`, world x axis towards `tracker[x_axis]`, z along the screen's normal
// (best-fit plane, pointing to the side of `viewer_side`, a tracker-frame point in
// front of the screen). kDegenerate for non-planar-fit failures or x_axis too close to
// the origin; kTooFewPoints for < 4 readings.
Result<TrackerRegistration> registerTrackerToScreen(std::span<const Vec3> tracker, size_t origin,
                                                    size_t x_axis, const Vec3& viewer_side);

}  // namespace procam::tracking
