// The "gpio" tilt driver: two ball tilt switches on a GPIO chip behind the plugin ABI.
// The coarse orientation is reported as its nominal specific force (ball_switch.hpp).
#include <cstring>
#include <exception>
#include <sstream>

#include "core/units.hpp"
#include "tilt/plugin/plugin_support.hpp"
#include "tilt/plugin/tilt_plugin.hpp"
#if PROCAM_TILT_GPIOD
#include "tilt/gpio/gpiod_lines.hpp"
#endif

namespace procam::tilt::plugin {
namespace {

#define PROCAM_GPIO_KEYS "chip", "lines", "debounce_ms", "tilt_deg", "table", PROCAM_TILT_GATE_KEYS

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
  return parts;
}

Result<CoarseOrientation> orientationNamed(const std::string& name) {
  if (name == "upright") return CoarseOrientation::kUpright;
  if (name == "left") return CoarseOrientation::kTiltedLeft;
  if (name == "right") return CoarseOrientation::kTiltedRight;
  if (name == "upside-down") return CoarseOrientation::kUpsideDown;
  return fail(ErrorCode::kInvalidInput,
              "gpio tilt: option table: '" + name + "' is not upright, left, right or upside-down");
}

Result<BallSwitchConfig> parseSwitch(const PluginOptions& o) {
  if (auto ok = o.onlyKnown({PROCAM_GPIO_KEYS}); !ok) return tl::unexpected(ok.error());
  BallSwitchConfig c;
  c.wait_ms = 0;  // polled by the daemon's timer: read() takes the queued edges only
  auto debounce = o.number("debounce_ms");
  auto tilt = o.number("tilt_deg");
  if (!debounce) return tl::unexpected(debounce.error());
  if (!tilt) return tl::unexpected(tilt.error());
  const double ms = debounce->value_or(20);
  const double deg = tilt->value_or(45);
  if (ms < 0 || ms > 10'000)
    return fail(ErrorCode::kInvalidInput, "gpio tilt: debounce_ms must be 0..10000");
  if (!(deg > 0 && deg <= 90))
    return fail(ErrorCode::kInvalidInput, "gpio tilt: tilt_deg must be in (0, 90]");
  c.debounce_ns = std::uint64_t(ms * 1e6);
  c.tilt_angle = degToRad(deg);
  if (auto table = o.text("table")) {
    const auto names = split(*table);
    if (names.size() != 4)
      return fail(ErrorCode::kInvalidInput,
                  "gpio tilt: option table needs four orientations (levels 00, 10, 01, 11)");
    for (std::size_t i = 0; i < 4; ++i) {
      auto named = orientationNamed(names[i]);
      if (!named) return tl::unexpected(named.error());
      c.table[i] = *named;
    }
  }
  return c;
}

int finish(std::unique_ptr<GpioLines> lines, const BallSwitchConfig& c, const PluginOptions& o,
           procam_device* out, char* err, std::size_t len) {
  SampleGateOptions defaults;
  defaults.stuck_limit = 0;  // a switch repeats its nominal vector until it moves
  auto gate = o.gate(defaults);
  if (!gate) return report(err, len, gate.error());
  return finishTiltDevice(std::make_unique<BallSwitchTilt>(std::move(lines), c), *gate, out, err,
                          len);
}

#if PROCAM_TILT_GPIOD
// A GPIO chip (udev role gpiochip) may carry ball switches; the lines come from the
// options, and any accelerometer outranks them.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_TILT) return 0;
  const std::string role = property(d, "PROCAM_ROLE");
  if (role != "tilt" && role != "gpiochip") return 0;
  const bool gpio = (d->subsystem && std::strcmp(d->subsystem, "gpio") == 0) ||
                    startsWith(d->devnode, "/dev/gpiochip");
  return gpio ? 20 : 0;
}

Result<std::vector<unsigned>> parseLines(const PluginOptions& o) {
  const auto text = o.text("lines");
  if (!text)
    return fail(ErrorCode::kInvalidInput,
                "gpio tilt: option lines is required (two line offsets, e.g. 17,27)");
  std::vector<unsigned> offsets;
  for (const std::string& part : split(*text)) {
    char* end = nullptr;
    const long v = std::strtol(part.c_str(), &end, 10);
    if (part.empty() || *end != '\0' || v < 0 || v > 4095)
      return fail(ErrorCode::kInvalidInput,
                  "gpio tilt: option lines: '" + part + "' is not a line offset");
    offsets.push_back(unsigned(v));
  }
  if (offsets.size() != 2)
    return fail(ErrorCode::kInvalidInput, "gpio tilt: option lines needs two offsets");
  return offsets;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  try {
    const PluginOptions o("gpio", config);
    auto c = parseSwitch(o);
    if (!c) return report(err, len, c.error());
    auto offsets = parseLines(o);
    if (!offsets) return report(err, len, offsets.error());
    const std::string chip = o.text("chip").value_or(d && d->devnode ? d->devnode : "");
    if (chip.empty())
      return report(err, len, "gpio tilt: no chip: give chip = gpiochipN or /dev/gpiochipN",
                    PROCAM_EINVAL);
    auto lines = GpiodLines::open(chip, *offsets);
    if (!lines) return report(err, len, "gpio tilt: " + lines.error().message, PROCAM_ENODEV);
    return finish(std::move(*lines), *c, o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}
#endif

}  // namespace

int createGpioOn(std::unique_ptr<GpioLines> lines, const procam_config* config, procam_device* out,
                 char* err, std::size_t len) {
  try {
    const PluginOptions o("gpio", config);
    auto c = parseSwitch(o);
    if (!c) return report(err, len, c.error());
    return finish(std::move(lines), *c, o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

#if PROCAM_TILT_GPIOD
const procam_driver_factory kGpioFactory = {PROCAM_FAMILY_TILT,
                                            "gpio",
                                            "two ball tilt switches on a GPIO chip (libgpiod)",
                                            &probe,
                                            &create,
                                            nullptr};
#endif

}  // namespace procam::tilt::plugin
