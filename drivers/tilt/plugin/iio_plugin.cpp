// The "iio" tilt driver: IioAccelerometer behind the plugin ABI.
#include <cstring>
#include <exception>
#include <filesystem>

#include "tilt/iio/iio_accelerometer.hpp"
#include "tilt/plugin/plugin_support.hpp"
#include "tilt/plugin/tilt_plugin.hpp"

namespace procam::tilt::plugin {
namespace {

constexpr const char* kDefaultSysfsRoot = "/sys/bus/iio/devices";

bool isIio(const procam_device_desc* d) {
  return (d->subsystem && std::strcmp(d->subsystem, "iio") == 0) ||
         startsWith(d->devnode, "/dev/iio:device") ||
         (d->syspath && std::strstr(d->syspath, "/iio:device"));
}

// udev (70-procamd.rules) gives accelerometers PROCAM_ROLE=tilt; other IIO devices
// (light, pressure) are not ours.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_TILT || property(d, "PROCAM_ROLE") != "tilt") return 0;
  return isIio(d) ? 60 : 0;
}

std::string baseName(const char* path) {
  return path ? std::filesystem::path(path).filename().string() : std::string();
}

Result<IioConfig> parse(const procam_device_desc* d, const PluginOptions& o) {
  if (auto ok = o.onlyKnown({"device_dir", "sysfs_root", "device_node", "buffered", "sampling_hz",
                             "buffer_length", PROCAM_TILT_GATE_KEYS});
      !ok)
    return tl::unexpected(ok.error());
  IioConfig c;
  // The device folder: given, or <sysfs_root>/<iio:deviceN> from the devnode or syspath.
  std::string device = baseName(d->devnode);
  if (device.empty()) device = baseName(d->syspath);
  if (auto dir = o.text("device_dir")) {
    c.device_dir = *dir;
  } else if (auto root = o.text("sysfs_root")) {
    if (device.empty())
      return fail(ErrorCode::kInvalidInput,
                  "iio tilt: sysfs_root needs a devnode or syspath naming iio:deviceN");
    c.device_dir = *root + "/" + device;
  } else if (d->syspath && *d->syspath) {
    c.device_dir = d->syspath;
  } else if (!device.empty()) {
    c.device_dir = std::string(kDefaultSysfsRoot) + "/" + device;
  } else {
    return fail(ErrorCode::kInvalidInput,
                "iio tilt: no device: give device_dir, or a devnode /dev/iio:deviceN");
  }
  c.device_node = o.text("device_node").value_or(d->devnode ? d->devnode : "");
  auto buffered = o.flag("buffered");
  auto hz = o.number("sampling_hz");
  auto length = o.integer("buffer_length");
  if (!buffered) return tl::unexpected(buffered.error());
  if (!hz) return tl::unexpected(hz.error());
  if (!length) return tl::unexpected(length.error());
  c.buffered = buffered->value_or(true);
  if (*hz && !(**hz > 0))
    return fail(ErrorCode::kInvalidInput, "iio tilt: sampling_hz must be > 0");
  c.sampling_hz = *hz;
  c.buffer_length = int(length->value_or(c.buffer_length));
  if (c.buffer_length < 1 || c.buffer_length > 65536)
    return fail(ErrorCode::kInvalidInput, "iio tilt: buffer_length must be 1..65536");
  c.poll_timeout_ms = 0;  // the daemon waits on poll_fd(); read() never blocks
  return c;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  try {
    const PluginOptions o("iio", config);
    auto c = parse(d, o);
    if (!c) return report(err, len, c.error());
    auto gate = o.gate({});
    if (!gate) return report(err, len, gate.error());
    return finishTiltDevice(std::make_unique<IioAccelerometer>(*c), *gate, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

}  // namespace

const procam_driver_factory kIioFactory = {
    PROCAM_FAMILY_TILT,
    "iio",
    "Linux IIO accelerometer (sysfs, or the buffer of /dev/iio:deviceN)",
    &probe,
    &create,
    nullptr};

}  // namespace procam::tilt::plugin
