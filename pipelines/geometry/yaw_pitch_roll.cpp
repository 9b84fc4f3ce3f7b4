#include "geometry/yaw_pitch_roll.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace procam::geom {
namespace {

Mat3 rotX(double a) {
  return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix();
}
Mat3 rotY(double a) {
  return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix();
}
Mat3 rotZ(double a) {
  return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix();
}

// Device axes at zero angles in the reference frame (columns): x = X, y = -Z, z = Y.
Mat3 reference() {
  Mat3 B;
  B << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return B;
}

}  // namespace

Mat3 worldFromDevice(const YawPitchRoll& a) {
  // Turn right (about -Z), tilt up (about the turned X), roll clockwise seen from behind
  // (about the optical axis Y), each about the device's own axes: intrinsic order.
  return rotZ(-a.yaw) * rotX(a.pitch) * rotY(a.roll) * reference();
}

Mat3 rotationFromAngles(const YawPitchRoll& a) {
  return worldFromDevice(a).transpose();
}

YawPitchRoll anglesFromRotation(const Mat3& R) {
  YawPitchRoll out;
  const Vec3 down = -R.col(2);  // world -Z in the device frame
  out.pitch = std::atan2(-down.z(), std::hypot(down.x(), down.y()));
  out.roll = std::atan2(down.x(), down.y());
  // Undo roll and pitch; what is left is rotZ(-yaw).
  const Mat3 rest = R.transpose() * reference().transpose() * rotY(out.roll).transpose() *
                    rotX(out.pitch).transpose();
  out.yaw = std::atan2(-rest(1, 0), rest(0, 0));
  return out;
}

Mat3 parentFromChild(const YawPitchRoll& a) {
  // The parent's frame is the reference frame seen through B.
  return reference().transpose() * worldFromDevice(a);
}

}  // namespace procam::geom
