#pragma once
// Device poses of scene files (see SCENE-FORMAT.md, "Poses"): world -> device poses from
// a centre and an orientation, rigid offsets of attached devices and their composition.
// Orientations given as angles follow geometry/yaw_pitch_roll.hpp, procamd's one
// yaw/pitch/roll convention; the scene reader converts the *_deg values of the file.
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::sim {

// Device pose (world -> device) from its centre and its world-from-device rotation.
geom::Pose poseFromCenter(const Vec3& center, const Mat3& world_from_device);

// Rigid offset of a child device expressed in its parent's frame, as the transform
// parent device -> child device (x_child = R x_parent + t).
geom::Pose childFromParent(const Vec3& position_in_parent, const Mat3& parent_from_child);

// Composition: world -> parent followed by parent -> child.
geom::Pose compose(const geom::Pose& child_from_parent, const geom::Pose& parent_from_world);

}  // namespace procam::sim
