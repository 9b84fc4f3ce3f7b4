#pragma once
// Pose of a known IR LED constellation (glasses, cap) from one calibrated camera:
// blob-to-LED matching by hypotheses (4 blobs x 4 LEDs, closed-form AP3P: OpenCV's
// SQPnP loses pixels in this near-affine setting), a loose reprojection gate on every
// LED, Levenberg-Marquardt PnP on the best assignments and a strict final gate.
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::tracking {

struct ConstellationOptions {
  double max_reprojection_px = 2.0;   // gate for a blob to count as an LED, and final RMS
  double hypothesis_gate_factor = 5;  // gate x this while scoring 4-point hypotheses
  int max_refinements = 8;            // best-scoring assignments refined by LM
  int min_leds = 4;                   // matched LEDs needed for a pose
  long max_hypotheses = 200000;       // kInvalidInput beyond (too many blobs x LEDs)
  double pixel_sigma = 0.1;           // blob noise, for the covariance
};

struct ConstellationPose {
  geom::Pose pose;               // constellation -> camera (x_cam = R x_led + t)
  Vec3 position_world;           // constellation origin in the world frame
  Mat3 covariance_world;         // of position_world, m^2 (first order, pixel_sigma)
  std::vector<int> blob_of_led;  // per LED: index into the blobs, -1 if unmatched
  int matched = 0;
  double rms_px = 0;  // reprojection RMS over the matched LEDs
};

// `leds`: LED positions in the constellation frame (>= 4, not all collinear).
// `blobs`: blob centres in the camera's (distorted) pixels. kNotFound when no
// hypothesis passes the gate with min_leds LEDs; kTooFewPoints for < 4 blobs or LEDs.
// `previous` (the last frame's pose, constellation -> camera) is tried first and kept
// when, refined, it explains every LED or every blob; the hypothesis search runs
// otherwise.
Result<ConstellationPose> estimateConstellationPose(
    const geom::CameraModel& camera, std::span<const Vec3> leds, std::span<const Vec2> blobs,
    const ConstellationOptions& options, const std::optional<geom::Pose>& previous = std::nullopt);

// First-order covariance of the constellation origin in the camera frame for a pose
// seen with isotropic pixel noise `sigma` on every LED in `used` (all when empty):
// sigma^2 (J^T J)^-1 over the 6 pose parameters, position block. Also the theoretical
// bound for a camera and a layout (f and distance decide whether the 2 mm RMS
// head-position bound can be met).
Mat3 positionCovariance(const geom::Intrinsics& K, const geom::Pose& pose,
                        std::span<const Vec3> leds, double sigma, std::span<const int> used = {});

}  // namespace procam::tracking
