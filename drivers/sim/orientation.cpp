#include "sim/orientation.hpp"

namespace procam::sim {

geom::Pose poseFromCenter(const Vec3& center, const Mat3& world_from_device) {
  geom::Pose pose;
  pose.R = world_from_device.transpose();
  pose.t = -pose.R * center;
  return pose;
}

geom::Pose childFromParent(const Vec3& position_in_parent, const Mat3& parent_from_child) {
  geom::Pose pose;
  pose.R = parent_from_child.transpose();
  pose.t = -pose.R * position_in_parent;
  return pose;
}

geom::Pose compose(const geom::Pose& child_from_parent, const geom::Pose& parent_from_world) {
  geom::Pose pose;
  pose.R = child_from_parent.R * parent_from_world.R;
  pose.t = child_from_parent.R * parent_from_world.t + child_from_parent.t;
  return pose;
}

}  // namespace procam::sim
