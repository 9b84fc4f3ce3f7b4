#pragma once
// The virtual rig's side of automatic keystone: the projector's intrinsics come
// from the scene, the tilt sensor's mount from its scene entry, and the
// accelerometer is calibrated at start the way a real rig is: the projector is
// posed with each sensor axis up and down in turn (six still holds, averaged),
// and keystone::calibrateSixPosition fits offset and gain. Pure computation on
// the scene; runs on a worker (it reads 6 x 10 s of simulated samples).
#include <string>

#include "auto_keystone.hpp"
#include "core/error.hpp"

namespace procam::daemon {

struct SimKeystoneSetup {
  ProjectorModel projector;
  TiltMount mount;
  double calibration_rms_g = 0;  // of the six-position fit
};

// kNotFound when the scene lacks the projector or the sensor; kIo when this
// procamd was built without the virtual rig.
Result<SimKeystoneSetup> simKeystoneSetup(const std::string& scene, const std::string& projector,
                                          const std::string& tilt_sensor);

}  // namespace procam::daemon
