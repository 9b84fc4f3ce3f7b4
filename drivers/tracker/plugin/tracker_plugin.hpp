#pragma once
// The head tracker drivers behind the plugin ABI (plugins/include/procamd/procam_plugin.h),
// one factory per file, in one plugin table: linked statically into procamd
// (procam_tracker_plugin_entry) and also built as the loadable procam-tracker.so.
// Options and probe scores: drivers/tracker/README.md.
#include <procamd/procam_plugin.h>

#include "tracking/led_tracker.hpp"

namespace procam::tracker::plugin {

extern const procam_driver_factory kIrCameraFactory;
extern const procam_driver_factory kHidFactory;  // Wii Remote IR camera (hid_plugin.hpp)

// The last frame's full result (raw, filtered, predicted) of a device made by the
// ir_camera driver; nullptr before its first pose.
const tracking::TrackedPose* irCameraLastPose(const procam_device& device);

}  // namespace procam::tracker::plugin

extern "C" const procam_plugin_table* procam_tracker_plugin_entry(void);
