#pragma once
// Projector orientation relative to a vertical wall ([Raskar02] §3.2.5: P_P = F[R 0], only the
// rotation matters; §6.2.2: tilt sensors give elevation and roll, the rigid camera gives
// the azimuth).
//
// Wall frame W (right-handed, +Z up as the world frame of ARCHITECTURE.md): X runs along the
// wall to the right, Y is horizontal and points into the wall (away from the viewer), Z
// points up. Projector frame: x right, y down, z forward (ARCHITECTURE.md). R maps W to the
// projector frame: x_p = R x_w.
//
// Angles: the yaw/pitch/roll convention of geometry/yaw_pitch_roll.hpp with the wall frame
// as its reference: square to the wall and upright at zero angles; positive yaw turns the
// optical axis to the right, positive pitch tilts it up, positive roll turns the image
// clockwise as seen from behind the projector.
#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/yaw_pitch_roll.hpp"

namespace procam::keystone {

using Angles = geom::YawPitchRoll;
// Wall frame -> projector rotation of those angles, and back (for |pitch| < 90°).
using geom::anglesFromRotation;
using geom::rotationFromAngles;

// Direction of gravity in the projector frame from a tilt sensor's specific force
// reading (gravity's reaction, +1 g "up" at rest) and the sensor -> projector mounting
// rotation: down = -mount * f.
Vec3 downFromSpecificForce(const Mat3& mount, const Vec3& specific_force);

// Pitch and roll from the direction of gravity in the projector frame (yaw = 0).
// Result: down = (sin r cos p, cos r cos p, -sin p). kInvalidInput for zero/NaN.
Result<Angles> tiltFromDown(const Vec3& down);

// Yaw and pitch from the wall normal in the projector frame, assuming zero roll (the
// projector's x axis level): the camera-only mode.
Result<Angles> anglesFromWallNormal(const Vec3& normal);

struct FusedOrientation {
  Mat3 R = Mat3::Identity();  // wall frame -> projector
  // Angle between the measured wall normal and the horizontal plane of the measured
  // gravity (0 for a truly vertical wall and perfect sensors): a consistency check.
  double wall_tilt = 0;
};

// Both sensors: gravity fixes pitch and roll exactly, the wall normal's horizontal
// part fixes yaw (§6.2.2). `normal` may have either sign. kDegenerate when the normal
// is (nearly) parallel to gravity (the wall is not vertical: no azimuth).
Result<FusedOrientation> fuseOrientation(const Vec3& down, const Vec3& normal);

// Tilt-only mode (no camera, like consumer projectors): yaw = 0.
Result<Mat3> rotationFromDown(const Vec3& down);
// Camera-only mode (no tilt sensor): roll = 0.
Result<Mat3> rotationFromWallNormal(const Vec3& normal);

}  // namespace procam::keystone
