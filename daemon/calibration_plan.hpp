#pragma once
// A calibrate run's plan and what it learnt, apart from the request that asked for it:
// the calibrate operation (commands_calibrate.cpp) and the drift correction's scans
// (drift_scan.cpp) choose the devices and route the same way and write the same
// rig-model entries.
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "calibration_job.hpp"
#include "device_set.hpp"
#include "rig/rig_model.hpp"

namespace procam::daemon {

// The devices and camera models of one projector's run, and its route: (b′) when asked
// for (a plane, a board or one camera named) or when one camera is all there is and the
// rig model knows the display plane; from cameras at several positions with a plane and
// several cameras; (a) otherwise. Everything but the capture itself.
tl::expected<CalibrationPlan, CalibrationFailure> makeCalibrationPlan(
    DeviceSet& devices, const CalibrationArgs& args, const CalibrationConfig& latency,
    const rig::RigModel& rig);

// What a run learnt, to merge into the rig model, and the reply that shows it in
// rig.json's own form.
struct Learnt {
  rig::RigModel update;
  std::map<std::string, std::string> meshes;  // file name -> PLY text
  nlohmann::json reply;
};

// One projector's outcome: route (a) gives it K, pose and its surface (a plane, or a
// mesh file); route (b′) its collineation with the display plane (no K, no pose), a plane
// given or found becoming the rig's surface; a measured response its photometric record.
Learnt learntFromRun(const CalibrationPlan& plan, const CalibrationOutcome& outcome);

}  // namespace procam::daemon
