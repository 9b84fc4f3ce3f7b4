#pragma once
// A device's pose refitted to image points of known world points, from its old pose
// (Levenberg-Marquardt: a bump is small), with its own intrinsics and lens distortion.
// Both drift corrections use it: the projector's (framebuffer pixels) and a fixed
// camera's. Pure.
#include <vector>

#include "core/error.hpp"
#include "geometry/camera_model.hpp"

namespace procam::drift {

// A correction needs this many registered tiles (the fits have 6 to 8 unknowns), and a
// refitted pose that misses them by more than this is refused: the tiles scatter by
// about 0.2 px about one collineation, so a worse fit is not a moved rigid device (a
// non-planar surface moved, a bad match).
inline constexpr int kMinCorrectionTiles = 8;
inline constexpr double kMaxRefitRmsPx = 1.0;

struct PoseRefit {
  geom::Pose pose;
  double rms_px = 0;  // reprojection RMS of the points
};

// kInvalidInput for lengths that differ or non-finite input; kTooFewPoints under 4;
// kNoConvergence when the solver fails or gives a non-finite pose.
Result<PoseRefit> refitPose(const geom::CameraModel& before, const std::vector<Vec3>& world,
                            const std::vector<Vec2>& pixels);

}  // namespace procam::drift
