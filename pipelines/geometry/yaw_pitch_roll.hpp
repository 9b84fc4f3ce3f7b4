#pragma once
// Yaw, pitch and roll: procamd's one convention for a device orientation given as three
// angles (ARCHITECTURE.md, "Frames and conventions"). The keystone pipelines, the
// keystone command line and the scene files of the virtual rig all use it.
//
// Reference frame: right-handed, +Z up (the world frame; for keystone the wall frame, X
// along the wall to the right, Y into the wall). At zero angles a device looks along +Y
// with its image upright: device x = +X, y = -Z, z = +Y. Then, applied in this order
// about the device's own axes:
//   yaw   > 0 turns the optical axis to the right, seen from above (about the down axis);
//   pitch > 0 tilts it up (about the device's x axis);
//   roll  > 0 turns the image clockwise as seen from behind the device, i.e. lowers its
//         right side (about the optical axis).
// In matrices: R_world<-device = Rz(-yaw) · Rx(pitch) · Ry(roll) · B, B = [X, -Z, Y]
// (columns), which is the aircraft convention (nose right, nose up, right wing down).
#include "core/types.hpp"

namespace procam::geom {

struct YawPitchRoll {
  double pitch = 0, roll = 0, yaw = 0;  // radians
};

// Columns are the device axes (x right, y down, z forward) in the reference frame.
Mat3 worldFromDevice(const YawPitchRoll& a);

// Reference frame -> device: x_device = R x_world (the transpose of worldFromDevice).
Mat3 rotationFromAngles(const YawPitchRoll& a);
// Inverse of rotationFromAngles for |pitch| < 90°.
YawPitchRoll anglesFromRotation(const Mat3& R);

// The same rules with a parent device as the reference (its up = -y, right = +x,
// forward = +z): columns are the child's axes in the parent's frame; zero angles give
// the identity.
Mat3 parentFromChild(const YawPitchRoll& a);

}  // namespace procam::geom
