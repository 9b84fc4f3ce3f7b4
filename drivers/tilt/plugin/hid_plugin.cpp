// The "hid" tilt driver: HID sensor accelerometers (with a sensor hub's gyrometer when the
// node has one) on /dev/hidrawN behind the plugin ABI.
#include <cstring>
#include <exception>

#include "tilt/plugin/plugin_support.hpp"
#include "tilt/plugin/tilt_plugin.hpp"

namespace procam::tilt::plugin {
namespace {

// hidraw nodes of head trackers carry PROCAM_ROLE=tracker and are not ours; a
// configured tilt device on a hidraw node is.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_TILT || property(d, "PROCAM_ROLE") != "tilt") return 0;
  const bool hidraw = (d->subsystem && std::strcmp(d->subsystem, "hidraw") == 0) ||
                      startsWith(d->devnode, "/dev/hidraw");
  return hidraw ? 40 : 0;
}

Result<std::string> parse(const procam_device_desc* d, const PluginOptions& o) {
  if (auto ok = o.onlyKnown({"hidraw", PROCAM_TILT_GATE_KEYS}); !ok)
    return tl::unexpected(ok.error());
  const std::string path = o.text("hidraw").value_or(d->devnode ? d->devnode : "");
  if (path.empty())
    return fail(ErrorCode::kInvalidInput, "hid tilt: no device: give hidraw = /dev/hidrawN");
  return path;
}

int finish(std::unique_ptr<HidTransport> transport, const PluginOptions& o, procam_device* out,
           char* err, std::size_t len) {
  auto gate = o.gate({});
  if (!gate) return report(err, len, gate.error());
  // Timeout 0: the daemon waits on poll_fd() (the hidraw node); read() never blocks.
  return finishTiltDevice(std::make_unique<HidAccelerometer>(std::move(transport), 0), *gate, out,
                          err, len);
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  try {
    const PluginOptions o("hid", config);
    auto path = parse(d, o);
    if (!path) return report(err, len, path.error());
    auto transport = HidrawTransport::open(*path);
    if (!transport)
      return report(err, len, "hid tilt: " + transport.error().message, PROCAM_ENODEV);
    return finish(std::move(*transport), o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

}  // namespace

int createHidOn(std::unique_ptr<HidTransport> transport, const procam_config* config,
                procam_device* out, char* err, std::size_t len) {
  try {
    const PluginOptions o("hid", config);
    if (auto ok = o.onlyKnown({"hidraw", PROCAM_TILT_GATE_KEYS}); !ok)
      return report(err, len, ok.error());
    return finish(std::move(transport), o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const procam_driver_factory kHidFactory = {
    PROCAM_FAMILY_TILT,
    "hid",
    "HID sensor accelerometer (usage 0x20/0x73) and gyrometer (0x20/0x76) on /dev/hidrawN",
    &probe,
    &create,
    nullptr};

}  // namespace procam::tilt::plugin
