#pragma once
// The camera drivers behind the plugin ABI (plugins/include/procamd/procam_plugin.h):
// replay, v4l2, and aravis / libcamera when their libraries were found, one factory
// each, in one plugin table linked statically into procamd. Options and probe scores:
// drivers/camera/README.md.
#include <procamd/procam_plugin.h>

namespace procam::camera::plugin {

extern const procam_driver_factory kReplayFactory;
#if PROCAM_CAMERA_ARAVIS
extern const procam_driver_factory kAravisFactory;
#endif
#if PROCAM_CAMERA_LIBCAMERA
extern const procam_driver_factory kLibcameraFactory;
#endif

}  // namespace procam::camera::plugin

extern "C" const procam_plugin_table* procam_camera_plugin_entry(void);
