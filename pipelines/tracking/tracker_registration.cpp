#include "tracking/tracker_registration.hpp"

#include <cmath>

#include "geometry/plane_fit.hpp"
#include "geometry/rigid.hpp"

namespace procam::tracking {

Result<TrackerRegistration> registerTracker(std::span<const Vec3> tracker,
                                            std::span<const Vec3> world, bool with_scale) {
  if (tracker.size() != world.size() || tracker.size() < 4)
    return fail(ErrorCode::kTooFewPoints, "tracker registration needs >= 4 point pairs");
  auto fit = geom::fitRigidTransform(tracker, world, with_scale);
  if (!fit) return tl::unexpected(fit.error());
  TrackerRegistration out;
  out.tracker_to_world.R = fit->R;
  out.tracker_to_world.t = fit->t;
  out.scale = fit->scale;
  out.rms = fit->rms;
  return out;
}

Result<TrackerRegistration> registerTrackerToScreen(std::span<const Vec3> tracker, size_t origin,
                                                    size_t x_axis, const Vec3& viewer_side) {
  if (tracker.size() < 4)
    return fail(ErrorCode::kTooFewPoints, "screen registration needs >= 4 tracker readings");
  if (origin >= tracker.size() || x_axis >= tracker.size() || origin == x_axis)
    return fail(ErrorCode::kInvalidInput, "origin and x-axis readings must be distinct indices");
  auto plane = geom::fitPlane(tracker);
  if (!plane) return tl::unexpected(plane.error());
  const Vec3& O = tracker[origin];
  Vec3 r3 = plane->plane.n;
  if (r3.dot(viewer_side - O) < 0) r3 = -r3;
  // [Raskar02] §4.2.5 normalises M_x - O directly; projecting it into the plane first keeps R
  // orthonormal when the readings are noisy.
  Vec3 r1 = tracker[x_axis] - O;
  r1 -= r1.dot(r3) * r3;
  const double extent = (tracker[x_axis] - O).norm();
  if (!(r1.norm() > 1e-6 * std::max(extent, 1e-12)) || !(extent > 0))
    return fail(ErrorCode::kDegenerate, "x-axis reading coincides with the origin or the normal");
  r1.normalize();
  TrackerRegistration out;
  out.tracker_to_world.R.row(0) = r1;  // R = [r1; r3 x r1; r3]
  out.tracker_to_world.R.row(1) = r3.cross(r1);
  out.tracker_to_world.R.row(2) = r3;
  out.tracker_to_world.t = -out.tracker_to_world.R * O;
  out.rms = plane->rms;  // off-plane scatter of the readings
  return out;
}

}  // namespace procam::tracking
