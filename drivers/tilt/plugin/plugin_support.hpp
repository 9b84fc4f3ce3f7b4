#pragma once
// What the four tilt plugin drivers share: the gate options and the device wrapper that
// puts an opened TiltSensor behind procam_tilt_ops (with the sample gate). Status codes,
// reasons and option parsing come from plugins/support. Nothing here throws.
#include <procamd/procam_plugin.h>

#include <cstdint>
#include <memory>
#include <string>

#include "support/driver_support.hpp"
#include "tilt/sample_gate.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::tilt::plugin {

using plugins::property;
using plugins::report;
using plugins::startsWith;
using plugins::statusOf;

// The driver options of procam_config (plugins/support), messages naming "<driver> tilt",
// with the gate keys every tilt driver accepts.
class PluginOptions : public plugins::DriverOptions {
 public:
  PluginOptions(const std::string& driver, const procam_config* config)
      : DriverOptions(driver + " tilt", config) {}

  // gate_range_g, min_norm_g, max_norm_g, stuck_limit (over the given defaults).
  Result<SampleGateOptions> gate(SampleGateOptions defaults) const;
};

// The gate keys, for onlyKnown() lists.
#define PROCAM_TILT_GATE_KEYS "gate_range_g", "min_norm_g", "max_norm_g", "stuck_limit"

// Opens `sensor` and fills `out` with a tilt device reading it through a SampleGate, the
// one place garbage tilt samples are dropped (procam_plugin.h, procam_tilt_counts).
// read(): PROCAM_OK with a sample; PROCAM_EAGAIN when no new sample is waiting or a
// garbage sample was dropped (and counted); PROCAM_EIO/ENODEV when the device fails.
// get_counts(): the gate's counts. poll_fd() is the sensor's pollFd().
int finishTiltDevice(std::unique_ptr<TiltSensor> sensor, const SampleGateOptions& gate,
                     procam_device* out, char* err, std::size_t len);

}  // namespace procam::tilt::plugin
