// The plugin table of the camera drivers (linked statically into procamd).
#include "camera/plugin/camera_plugin.hpp"

extern "C" const procam_plugin_table* procam_camera_plugin_entry(void) {
  using namespace procam::camera::plugin;
  // Built on first call: the factories live in other translation units.
  static const procam_driver_factory factories[] = {
    kReplayFactory,
    kV4l2Factory,
#if PROCAM_CAMERA_ARAVIS
    kAravisFactory,
#endif
#if PROCAM_CAMERA_LIBCAMERA
    kLibcameraFactory,
#endif
  };
  static const procam_plugin_table table = {PROCAM_PLUGIN_ABI_VERSION, "camera", "1",
                                            sizeof(factories) / sizeof(factories[0]), factories};
  return &table;
}
