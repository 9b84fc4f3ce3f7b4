#include "sim/orientation.hpp"

#include <Eigen/Geometry>

namespace procam::sim {

namespace {
Mat3 axisRotation(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}
}  // namespace

Mat3 worldFromDeviceYpr(double yaw, double pitch, double roll) {
  // Device axes at zero angles: x = +X (right), y = -Z (down), z = +Y (forward).
  Mat3 base;
  base.col(0) = Vec3::UnitX();
  base.col(1) = -Vec3::UnitZ();
  base.col(2) = Vec3::UnitY();
  return axisRotation(Vec3::UnitZ(), yaw) * axisRotation(Vec3::UnitX(), pitch) *
         axisRotation(Vec3::UnitY(), roll) * base;
}

Mat3 parentFromChildYpr(double yaw, double pitch, double roll) {
  return axisRotation(-Vec3::UnitY(), yaw) * axisRotation(Vec3::UnitX(), pitch) *
         axisRotation(Vec3::UnitZ(), roll);
}

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
