// The plugin table of the head tracker drivers (linked statically into procamd, and the
// entry of procam-tracker.so).
#include "tracker/plugin/tracker_plugin.hpp"

extern "C" const procam_plugin_table* procam_tracker_plugin_entry(void) {
  using namespace procam::tracker::plugin;
  // Built on first call: the factories live in other translation units.
  static const procam_driver_factory factories[] = {
      kIrCameraFactory,
      kHidFactory,
  };
  static const procam_plugin_table table = {PROCAM_PLUGIN_ABI_VERSION, "tracker", "1",
                                            sizeof(factories) / sizeof(factories[0]), factories};
  return &table;
}
