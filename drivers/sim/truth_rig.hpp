#pragma once
// A scene's truth as a rig model (procam-sim truth --rig-json): what a test hands
// procamd explicitly (`procamd --rig FILE`) when it wants a known rig instead of
// calibrating one. Cameras and projectors at `time` with their true K, distortion
// and pose; each tilt sensor's true mount on its projector with an accelerometer
// calibration done the way a rig is calibrated (six still holds of simulated,
// noisy samples, fitted by keystone::calibrateSixPosition, so that the offset and
// gain are estimates, not the scene's bias); the plane a projector's central ray
// lights when that surface is planar; the scene's viewer.
#include "core/error.hpp"
#include "rig/rig_model.hpp"
#include "sim/scene.hpp"

namespace procam::sim {

Result<rig::RigModel> truthRig(const Scene& scene, double time);

}  // namespace procam::sim
