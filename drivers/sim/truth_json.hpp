#pragma once
// Ground truth of the rig at one time as JSON: every projector's and camera's K,
// R, t (world -> device), centre, P = K[R|t], resolution, distortion; tilt-sensor
// mounts and their noise-free reading; trackers; the viewer; surfaces.
#include <nlohmann/json.hpp>

#include "sim/scene.hpp"

namespace procam::sim {

nlohmann::json truthJson(const Scene& scene, const SceneState& state);

}  // namespace procam::sim
