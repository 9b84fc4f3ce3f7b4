#pragma once
// Orientation conventions of scene files (see SCENE-FORMAT.md, "Poses").
// Angles are radians here; the scene reader converts the *_deg values of the file.
//
// A yaw/pitch/roll triple is applied intrinsically: yaw about the reference "up"
// axis, then pitch about the (yawed) "right" axis, then roll about the resulting
// "forward" axis, each right-handed. So positive yaw turns left (seen from above),
// positive pitch raises the nose, positive roll lowers the right side.
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::sim {

inline constexpr double kPi = 3.14159265358979323846;
inline double degToRad(double deg) {
  return deg * kPi / 180.0;
}
inline double radToDeg(double rad) {
  return rad * 180.0 / kPi;
}

// Columns are the device axes (x right, y down, z forward) in world coordinates
// for a device in the world frame (up = +Z, right = +X, forward = +Y at zero angles).
Mat3 worldFromDeviceYpr(double yaw, double pitch, double roll);

// Columns are the child axes in the parent device frame (up = -y, right = +x,
// forward = +z); zero angles give the identity.
Mat3 parentFromChildYpr(double yaw, double pitch, double roll);

// Device pose (world -> device) from its centre and its world-from-device rotation.
geom::Pose poseFromCenter(const Vec3& center, const Mat3& world_from_device);

// Rigid offset of a child device expressed in its parent's frame, as the transform
// parent device -> child device (x_child = R x_parent + t).
geom::Pose childFromParent(const Vec3& position_in_parent, const Mat3& parent_from_child);

// Composition: world -> parent followed by parent -> child.
geom::Pose compose(const geom::Pose& child_from_parent, const geom::Pose& parent_from_world);

}  // namespace procam::sim
