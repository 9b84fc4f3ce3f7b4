#pragma once
// Automatic keystone, the daemon's side: the pure parts live in pipelines/keystone (the
// tilt tracker, the solve from gravity, the six-position calibration); here they meet
// the configuration ([keystone] in procamd.toml).
#include "config.hpp"
#include "core/error.hpp"
#include "keystone/keystone_from_down.hpp"
#include "keystone/six_position.hpp"
#include "keystone/tilt_filter.hpp"
#include "keystone/tilt_tracker.hpp"

namespace procam::daemon {

using keystone::KeystoneEstimate;
using keystone::ProjectorModel;
using keystone::SixPositionCollector;
using keystone::solveFromDown;
using keystone::TiltMount;
using keystone::TiltTracker;

// The mount and calibration of [keystone] in procamd.toml; kInvalidInput when
// the mount is not a rotation.
Result<TiltMount> mountFromConfig(const KeystoneConfig& config);

// The tilt filter of [keystone] (cutoff_hz, hysteresis_deg).
keystone::TiltFilterOptions tiltFilterOptions(const KeystoneConfig& config);

}  // namespace procam::daemon
