#pragma once
// A projector's k·B on the object (eq. 5.4's diffuse reflectance times the projector's
// brightness), measured: a calibrated camera captures the object with the projector at
// full white and at black; each camera pixel whose ray meets the object where the
// projector lights it well inside its reach gives (white − black) · d² / cos θ_P, and the
// median over them, per channel, is the gain in the camera's linear units. The frames'
// white level and the appearance are then in the same units. The camera must be linear
// (response gamma 1) and its captures unsaturated where they count; the rig's geometry
// (camera pose, projector pose, object) comes from the rig model.
#include <functional>
#include <opencv2/core.hpp>
#include <span>

#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "shader_lamps/lamp_weights.hpp"
#include "shader_lamps/object_model.hpp"

namespace procam::lamps {

struct GainMeasurement {
  Vec3 gain_rgb = Vec3::Zero();  // camera units at 1 m, normal incidence, full white
  long samples = 0;              // camera pixels used
  double spread = 0;             // median absolute deviation / median (green), a quality figure
};

struct GainCapture {
  const geom::CameraModel* camera = nullptr;
  cv::Mat white, black;     // CV_8U or CV_16U, 1 (grey) or 3 (B, G, R) channels, the camera's size
  double saturation = 255;  // codes at or above this are clipped, not light
  int step = 2;             // camera pixels between samples
};

// Projector `index` of `lamps` (their weights' reach tells where it lights the object
// well). kInvalidInput for bad images, an index out of range or a step outside [1, 64];
// kTooFewPoints with fewer than 50 usable pixels (the camera does not see the projector's
// light on the object, or only saturated or under 2 % of saturation).
Result<GainMeasurement> measureLampGain(std::span<const Lamp> lamps, const LampWeights& weights,
                                        std::size_t index, const ObjectModel& object,
                                        const GainCapture& capture);

// The same from a projector's brightness across its frame as a rig's calibration keeps it
// (white minus black seen by a camera at each framebuffer pixel, in that camera's units,
// one channel): the median of brightness · d² / cos θ_P over the pixels that light the
// object at least `inside_px` inside their reach (the map is interpolated between nodes
// that may straddle the object's edge; the median keeps to the object's own). Grey: the
// object's colour is not in it. kTooFewPoints under 50 such pixels; kInvalidInput for a
// reach of another size.
Result<GainMeasurement> gainFromBrightness(const LampView& view, const cv::Mat& reach,
                                           const std::function<double(const Vec2&)>& brightness,
                                           double inside_px = 3);

}  // namespace procam::lamps
