// procam-tracker.so: the head tracker drivers as a loadable plugin (the same table
// procamd links statically).
#include "tracker/plugin/tracker_plugin.hpp"

PROCAM_PLUGIN_DEFINE(procam_tracker_plugin_entry)
