#pragma once
// The mock drivers of the virtual rig as a static driver plugin: one factory
// per family, all probing devices of subsystem "sim" (score 100, above any
// hardware driver). A device description names its scene and device with the
// properties SIM_SCENE and SIM_DEVICE.
#include "procamd/procam_plugin.h"

extern "C" const procam_plugin_table* procam_sim_plugin_entry(void);
