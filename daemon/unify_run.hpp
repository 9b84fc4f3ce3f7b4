#pragma once
// The end of a calibrate run of route (a) over several projectors: each projector's mesh
// was triangulated on its own; where they overlap they are unified ([Raskar02] eq. 4.4,
// surface/mesh_unification.hpp) before rig.json and the meshes are written, so that the
// projectors agree about the surface they share.
#include <nlohmann/json.hpp>
#include <span>

#include "calibration_job.hpp"

namespace procam::daemon {

// Unifies the meshes of the run's route (a) outcomes in place. The reply's `unified`
// record ({meshes, vertices, shared, gap_rms_mm, gap_max_mm, gap_after_rms_mm,
// gap_after_max_mm}), or null when fewer than two projectors have a mesh.
tl::expected<nlohmann::json, CalibrationFailure> unifyRunMeshes(
    std::span<const CalibrationPlan* const> plans, std::span<CalibrationOutcome> outcomes);

}  // namespace procam::daemon
