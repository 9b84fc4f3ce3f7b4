// The "i2c" tilt driver: the register-level ADXL345 / MPU-6050 / LIS3DH drivers on
// /dev/i2c-N behind the plugin ABI.
#include <cstring>
#include <exception>

#include "tilt/i2c/i2c_accelerometer.hpp"
#include "tilt/i2c/i2c_dev_bus.hpp"
#include "tilt/plugin/plugin_support.hpp"
#include "tilt/plugin/tilt_plugin.hpp"

namespace procam::tilt::plugin {
namespace {

bool isI2c(const procam_device_desc* d) {
  return (d->subsystem && std::strcmp(d->subsystem, "i2c-dev") == 0) ||
         startsWith(d->devnode, "/dev/i2c-");
}

// An I2C adapter (udev role i2c-adapter) may carry an accelerometer; which chip and
// where comes from the options, so an IIO driver of the same sensor outranks this one.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_TILT) return 0;
  const std::string role = property(d, "PROCAM_ROLE");
  if (role != "tilt" && role != "i2c-adapter") return 0;
  return isI2c(d) ? 40 : 0;
}

struct I2cOptions {
  std::string bus;
  I2cChip chip = I2cChip::kMpu6050;
  std::uint16_t address = 0;
  I2cAccelConfig accel;
};

Result<I2cOptions> parse(const procam_device_desc* d, const PluginOptions& o) {
  if (auto ok =
          o.onlyKnown({"bus", "chip", "address", "range_g", "rate_hz", PROCAM_TILT_GATE_KEYS});
      !ok)
    return tl::unexpected(ok.error());
  I2cOptions c;
  const auto chip = o.text("chip");
  if (!chip)
    return fail(ErrorCode::kInvalidInput,
                "i2c tilt: option chip is required (adxl345, mpu6050 or lis3dh)");
  auto parsed = parseI2cChip(*chip);
  if (!parsed)
    return fail(ErrorCode::kInvalidInput,
                "i2c tilt: option chip: '" + *chip + "' is not adxl345, mpu6050 or lis3dh");
  c.chip = *parsed;
  // bus: a path, or the adapter number N of /dev/i2c-N; default the device's node.
  c.bus = o.text("bus").value_or(d->devnode ? d->devnode : "");
  if (c.bus.empty())
    return fail(ErrorCode::kInvalidInput, "i2c tilt: no bus: give bus = N or /dev/i2c-N");
  if (c.bus.find_first_not_of("0123456789") == std::string::npos) c.bus = "/dev/i2c-" + c.bus;
  auto address = o.integer("address");
  auto range = o.number("range_g");
  auto rate = o.number("rate_hz");
  if (!address) return tl::unexpected(address.error());
  if (!range) return tl::unexpected(range.error());
  if (!rate) return tl::unexpected(rate.error());
  const long a = address->value_or(defaultAddress(c.chip));
  if (a < 0x03 || a > 0x77)
    return fail(ErrorCode::kInvalidInput,
                "i2c tilt: address must be a 7-bit address 0x03..0x77, not " + std::to_string(a));
  c.address = std::uint16_t(a);
  c.accel.range_g = range->value_or(c.accel.range_g);
  c.accel.rate_hz = rate->value_or(c.accel.rate_hz);
  if (!(c.accel.range_g > 0) || !(c.accel.rate_hz > 0))
    return fail(ErrorCode::kInvalidInput, "i2c tilt: range_g and rate_hz must be > 0");
  // One data-ready check per read(): the daemon polls by timer and must not block.
  c.accel.max_polls = 1;
  c.accel.poll_interval = {};
  return c;
}

int finish(std::shared_ptr<I2cBus> bus, const I2cOptions& c, const PluginOptions& o,
           procam_device* out, char* err, std::size_t len) {
  auto sensor = makeI2cAccelerometer(c.chip, std::move(bus), c.address, c.accel);
  auto gate = o.gate({});
  if (!gate) return report(err, len, gate.error());
  return finishTiltDevice(std::move(sensor), *gate, out, err, len);
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  try {
    const PluginOptions o("i2c", config);
    auto c = parse(d, o);
    if (!c) return report(err, len, c.error());
    auto bus = I2cDevBus::open(c->bus);
    if (!bus) return report(err, len, "i2c tilt: " + bus.error().message, PROCAM_ENODEV);
    return finish(std::make_shared<I2cDevBus>(std::move(*bus)), *c, o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

}  // namespace

int createI2cOn(std::shared_ptr<I2cBus> bus, const procam_device_desc* d,
                const procam_config* config, procam_device* out, char* err, std::size_t len) {
  try {
    const PluginOptions o("i2c", config);
    auto c = parse(d, o);
    if (!c) return report(err, len, c.error());
    return finish(std::move(bus), *c, o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const procam_driver_factory kI2cFactory = {
    PROCAM_FAMILY_TILT,
    "i2c",
    "ADXL345, MPU-6050 or LIS3DH on /dev/i2c-N (register level)",
    &probe,
    &create,
    nullptr};

}  // namespace procam::tilt::plugin
