#pragma once
// The "hid" tracker driver's entry points beside its factory (kHidFactory in
// tracker_plugin.hpp): creation on a given transport and clock (stored report streams
// in tests), and the full result of the last report.
#include <procamd/procam_plugin.h>

#include <memory>

#include "tracker/hid/wiimote_ir_source.hpp"
#include "tracking/led_tracker.hpp"

namespace procam::tracker::plugin {

// As kHidFactory.create, on `transport` instead of a hidraw node (the hidraw option is
// ignored); `clock` stamps the reports (CLOCK_MONOTONIC when empty).
int createWiimoteOn(std::unique_ptr<wiimote::WiimoteTransport> transport,
                    const procam_config* config, wiimote::Clock clock, procam_device* out,
                    char* err, std::size_t len);

// The last report's full result (raw, filtered, predicted) of a device made by the hid
// driver; nullptr before its first pose or for other devices.
const tracking::TrackedPose* wiimoteLastPose(const procam_device& device);

}  // namespace procam::tracker::plugin
