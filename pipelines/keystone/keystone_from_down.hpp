#pragma once
// Tilt-only automatic keystone: the pre-warp homography for a measured direction of
// gravity ([Raskar02] §3.2.5 with §6.2.2: gravity fixes pitch and roll; yaw needs a
// camera and is taken as 0).
#include <string>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "keystone/orientation.hpp"

namespace procam::keystone {

// What the solve needs to know about the projector.
struct ProjectorModel {
  geom::Intrinsics K;
  int width = 0, height = 0;
  std::string source;  // where K came from, for messages
};

// One keystone solution for a content size.
struct KeystoneEstimate {
  Mat3 H = Mat3::Identity();  // content pixels -> framebuffer pixels, H(2,2) = 1
  Vec3 down = Vec3::UnitY();  // gravity, projector frame
  Angles angles;              // pitch and roll from gravity; yaw 0 or the camera's
  double scale = 0;           // linear size relative to the uncorrected image
  int content_width = 0, content_height = 0;
  double sample_time = 0;  // s, the tilt sample's timestamp (set by the caller)
};

// The pre-warp for gravity `down` (projector frame). tiltFromDown's and
// solveKeystone's errors (a tilt so steep that the image misses the wall).
Result<KeystoneEstimate> solveFromDown(const ProjectorModel& projector, const Vec3& down,
                                       int content_width, int content_height);

// The pre-warp for a full orientation R (wall frame -> projector: gravity's pitch and
// roll with the yaw a camera measured, fuseOrientation); `down` is reported as given.
// solveKeystone's errors.
Result<KeystoneEstimate> solveFromOrientation(const ProjectorModel& projector, const Mat3& R,
                                              const Vec3& down, int content_width,
                                              int content_height);

}  // namespace procam::keystone
