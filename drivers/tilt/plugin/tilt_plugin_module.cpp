// procam-tilt.so: the tilt drivers as a loadable plugin (the same table procamd links
// statically).
#include "tilt/plugin/tilt_plugin.hpp"

PROCAM_PLUGIN_DEFINE(procam_tilt_plugin_entry)
