#pragma once
// The camera drivers behind the plugin ABI (plugins/include/procamd/procam_plugin.h):
// replay, v4l2, and aravis / libcamera when their libraries were found, one factory
// each, in one plugin table linked statically into procamd. Options and probe scores:
// drivers/camera/README.md.
#include <procamd/procam_plugin.h>

#include <cstddef>
#include <memory>

#include "camera/v4l2/v4l2_io.hpp"

namespace procam::camera::plugin {

extern const procam_driver_factory kReplayFactory;
extern const procam_driver_factory kV4l2Factory;
#if PROCAM_CAMERA_ARAVIS
extern const procam_driver_factory kAravisFactory;
#endif
#if PROCAM_CAMERA_LIBCAMERA
extern const procam_driver_factory kLibcameraFactory;
#endif

// The v4l2 driver's create() on the given kernel calls (tests pass a fake device).
int createV4l2On(std::unique_ptr<V4l2Io> io, const procam_device_desc* desc,
                 const procam_config* config, procam_device* out, char* err, std::size_t len);

}  // namespace procam::camera::plugin

extern "C" const procam_plugin_table* procam_camera_plugin_entry(void);
