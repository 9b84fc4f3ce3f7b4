// The plugin table of the tilt drivers (linked statically into procamd, and the entry
// of procam-tilt.so).
#include "tilt/plugin/tilt_plugin.hpp"

extern "C" const procam_plugin_table* procam_tilt_plugin_entry(void) {
  using namespace procam::tilt::plugin;
  // Built on first call: the factories live in other translation units.
  static const procam_driver_factory factories[] = {
    kIioFactory,
    kI2cFactory,
    kHidFactory,
#if PROCAM_TILT_GPIOD
    kGpioFactory,
#endif
  };
  static const procam_plugin_table table = {PROCAM_PLUGIN_ABI_VERSION, "tilt", "1",
                                            sizeof(factories) / sizeof(factories[0]), factories};
  return &table;
}
