#pragma once
// What the four tilt plugin drivers share: text options, the device wrapper that puts
// an opened TiltSensor behind procam_tilt_ops (with the sample gate), and the mapping
// of procam::Error to the ABI's status codes. Nothing here throws.
#include <procamd/procam_plugin.h>

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>

#include "tilt/sample_gate.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::tilt::plugin {

// Writes `message` into the caller's buffer and returns `status`.
int report(char* err, std::size_t len, const std::string& message, int status);
// PROCAM_E* for an error: kNotFound -> ENODEV, kInvalidInput/kParse -> EINVAL, kIo -> EIO.
int statusOf(ErrorCode code);
// report() of an Error with its status.
int report(char* err, std::size_t len, const Error& error);

// The driver options of procam_config, checked against the keys a driver knows.
class PluginOptions {
 public:
  PluginOptions(std::string driver, const procam_config* config);

  // kInvalidInput naming the first key not in `known` (and listing them).
  Result<void> onlyKnown(std::initializer_list<const char*> known) const;
  std::optional<std::string> text(const char* key) const;
  // Decimal or 0x-prefixed integer; kInvalidInput "option K: 'V' is not ..." otherwise.
  Result<std::optional<long>> integer(const char* key) const;
  Result<std::optional<double>> number(const char* key) const;  // finite
  Result<std::optional<bool>> flag(const char* key) const;      // true/false/1/0/yes/no
  // The gate keys every tilt driver accepts: gate_range_g, min_norm_g, max_norm_g,
  // stuck_limit (over the given defaults).
  Result<SampleGateOptions> gate(SampleGateOptions defaults) const;

  const std::string& driver() const { return driver_; }

 private:
  std::string driver_;
  const procam_config* config_;
};

// The gate keys, for onlyKnown() lists.
#define PROCAM_TILT_GATE_KEYS "gate_range_g", "min_norm_g", "max_norm_g", "stuck_limit"

// A udev/config property of a device description, empty when absent.
std::string property(const procam_device_desc* d, const char* key);
bool startsWith(const char* text, const char* prefix);

// Opens `sensor` and fills `out` with a tilt device reading it through a SampleGate.
// read(): PROCAM_OK with a sample; PROCAM_EAGAIN when no new sample is waiting, or
// with PROCAM_TILT_REJECTED_PREFIX when a garbage sample was dropped (and counted);
// PROCAM_EIO/ENODEV when the device fails. poll_fd() is the sensor's pollFd().
int finishTiltDevice(std::unique_ptr<TiltSensor> sensor, const SampleGateOptions& gate,
                     procam_device* out, char* err, std::size_t len);

// The gate counts of a device made by finishTiltDevice.
const SampleCounts& tiltDeviceCounts(const procam_device& device);

}  // namespace procam::tilt::plugin
