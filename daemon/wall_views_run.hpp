#pragma once
// The end of a calibrate run of route (b′) from cameras at several positions: every
// projector has been scanned by every camera (calibration_job.hpp, the outcomes'
// wall_nodes); here they are solved together (calib::solveWallViews, [Chen02]'s
// homography tree) and the reply's `wall` record is made.
#include <nlohmann/json.hpp>
#include <span>

#include "calibration/wall_views_route.hpp"
#include "calibration_job.hpp"

namespace procam::daemon {

// Route (b′) from cameras at several positions: the projectors of a run, scanned (their
// outcomes' wall_nodes), solved together through the homography tree; each outcome gets
// its `planar` result. The reply part of the tree: `wall` (wallViewsJson).
tl::expected<calib::WallViewsResult, CalibrationFailure> solveWallViewsRun(
    std::span<const CalibrationPlan* const> plans, std::span<CalibrationOutcome> outcomes);
nlohmann::json wallViewsJson(const calib::WallViewsResult& result,
                             std::span<const CalibrationPlan* const> plans);

}  // namespace procam::daemon
