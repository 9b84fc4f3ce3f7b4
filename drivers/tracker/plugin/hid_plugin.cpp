// The "hid" tracker driver: a Wii Remote's IR camera on /dev/hidrawN (WiimoteTracker)
// behind the plugin ABI, with the LED layout, filter and registration options every IR
// LED tracker shares (led_tracker_options.hpp) and the Wii camera's model as default
// intrinsics.
#include "tracker/plugin/hid_plugin.hpp"

#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "tracker/hid/wiimote_tracker.hpp"
#include "tracker/plugin/led_tracker_options.hpp"
#include "tracker/plugin/tracker_plugin.hpp"

namespace procam::tracker::plugin {
namespace {

using plugins::DriverOptions;
using plugins::property;
using plugins::report;
namespace wm = wiimote;

constexpr const char* kWho = "hid tracker";

#define PROCAM_HID_TRACKER_KEYS                                          \
  "hidraw", "ir_format", "sensitivity", "player_leds", "ack_timeout_ms", \
      PROCAM_TRACKER_CAMERA_KEYS, PROCAM_LED_TRACKER_KEYS

bool isWiiId(unsigned vendor, unsigned product) {
  return vendor == wm::kVendorNintendo &&
         (product == wm::kProductWiimote || product == wm::kProductWiimotePlus);
}

// udev/70-procamd.rules imports the parent hid device's HID_ID, "bus:vendor:product"
// (hex); the hid device's name in the syspath, "bus:VENDOR:PRODUCT.instance", says the
// same where the property is missing.
bool isWiimote(const procam_device_desc* d) {
  unsigned bus = 0, vendor = 0, product = 0;
  const std::string hid_id = property(d, "HID_ID");
  if (std::sscanf(hid_id.c_str(), "%x:%x:%x", &bus, &vendor, &product) == 3)
    return isWiiId(vendor, product);
  const std::string syspath = d->syspath ? d->syspath : "";
  for (std::size_t at = syspath.find('/'); at != std::string::npos;
       at = syspath.find('/', at + 1)) {
    char dot = 0;
    if (std::sscanf(syspath.c_str() + at + 1, "%4x:%4x:%4x%c", &bus, &vendor, &product, &dot) ==
            4 &&
        dot == '.' && isWiiId(vendor, product))
      return true;
  }
  return false;
}

// A Wii Remote's hidraw node, tagged as a tracker by the udev rule; a tracker configured
// on a hidraw node (no udev properties then) is most likely one too. Other hidraw
// trackers (TrackIR) are not ours.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_TRACKER || property(d, "PROCAM_ROLE") != "tracker") return 0;
  if (d->subsystem && std::strcmp(d->subsystem, "hidraw") == 0) return isWiimote(d) ? 60 : 0;
  return plugins::startsWith(d->devnode, "/dev/hidraw") ? 30 : 0;
}

int readPose(void* self, procam_pose_sample* out, char* err, std::size_t len) {
  try {
    auto* tracker = static_cast<wm::WiimoteTracker*>(self);
    auto pose = tracker->read(0);  // the daemon waits on poll_fd
    if (!pose) {
      const ErrorCode c = pose.error().code;
      const bool again = c == ErrorCode::kNotFound || c == ErrorCode::kTooFewPoints;
      return report(err, len, pose.error().message, again ? PROCAM_EAGAIN : plugins::statusOf(c));
    }
    *out = wm::WiimoteTracker::sample(*pose, tracker->lastTimestampNs());
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const procam_tracker_ops kOps = {PROCAM_TRACKER_OPS_VERSION, &readPose, nullptr};

int pollFd(void* self) {
  return static_cast<wm::WiimoteTracker*>(self)->pollFd();
}

void destroy(void* self) {
  delete static_cast<wm::WiimoteTracker*>(self);
}

// The configuration with the Wii camera's intrinsics first: the user's fx fy cx cy
// (later, so they win) override them.
struct WithDefaults {
  std::vector<std::string> text;
  std::vector<procam_kv> kv;
  procam_config config{};

  explicit WithDefaults(const procam_config* user) {
    const geom::CameraModel cam = wm::wiimoteCamera();
    const std::pair<const char*, double> defaults[] = {
        {"fx", cam.K.fx}, {"fy", cam.K.fy}, {"cx", cam.K.cx}, {"cy", cam.K.cy}};
    text.reserve(4);
    for (const auto& [key, value] : defaults) {
      char number[32];
      std::snprintf(number, sizeof number, "%.17g", value);
      text.emplace_back(number);
    }
    for (std::size_t i = 0; i < 4; ++i) kv.push_back({defaults[i].first, text[i].c_str()});
    for (std::size_t i = 0; user && i < user->n_options; ++i) kv.push_back(user->options[i]);
    config = {kv.data(), kv.size()};
  }
};

struct Parsed {
  wm::WiimoteIrOptions ir;
  geom::CameraModel camera;
  tracking::LedTrackerOptions tracker;
};

Result<wm::WiimoteIrOptions> irOptions(const DriverOptions& o) {
  wm::WiimoteIrOptions ir;
  if (const auto format = o.text("ir_format")) {
    if (*format == "extended")
      ir.format = wm::IrFormat::kExtended;
    else if (*format == "basic")
      ir.format = wm::IrFormat::kBasic;
    else
      return fail(ErrorCode::kInvalidInput,
                  o.who() + ": option ir_format: '" + *format + "' is not extended or basic");
  }
  int leds = ir.leds;
  struct Range {
    const char* key;
    long lo, hi;
    int* value;
  };
  for (const Range r :
       {Range{"sensitivity", 1, 5, &ir.sensitivity}, Range{"player_leds", 0, 15, &leds},
        Range{"ack_timeout_ms", 1, 10000, &ir.ack_timeout_ms}}) {
    auto v = o.integer(r.key);
    if (!v) return tl::unexpected(v.error());
    if (!*v) continue;
    if (**v < r.lo || **v > r.hi)
      return fail(ErrorCode::kInvalidInput, o.who() + ": option " + r.key + " must be " +
                                                std::to_string(r.lo) + ".." + std::to_string(r.hi));
    *r.value = static_cast<int>(**v);
  }
  ir.leds = static_cast<std::uint8_t>(leds);
  return ir;
}

Result<Parsed> parse(const DriverOptions& o) {
  if (auto ok = o.onlyKnown({PROCAM_HID_TRACKER_KEYS}); !ok) return tl::unexpected(ok.error());
  auto ir = irOptions(o);
  if (!ir) return tl::unexpected(ir.error());
  auto cam = trackerCamera(o);
  if (!cam) return tl::unexpected(cam.error());
  cam->width = wm::kIrWidth;
  cam->height = wm::kIrHeight;
  auto tracker = ledTrackerOptions(o);
  if (!tracker) return tl::unexpected(tracker.error());
  return Parsed{*ir, *cam, std::move(*tracker)};
}

int finish(std::unique_ptr<wm::WiimoteTransport> transport, const Parsed& p, wm::Clock clock,
           procam_device* out, char* err, std::size_t len) {
  auto source = wm::WiimoteIrSource::start(std::move(transport), p.ir, std::move(clock));
  if (!source) return report(err, len, source.error());
  auto tracker = wm::WiimoteTracker::create(std::move(*source), p.camera, p.tracker);
  if (!tracker) return report(err, len, tracker.error());
  *out = {};
  out->family = PROCAM_FAMILY_TRACKER;
  out->self = new wm::WiimoteTracker(std::move(*tracker));
  out->poll_fd = &pollFd;
  out->destroy = &destroy;
  out->ops.tracker = &kOps;
  return PROCAM_OK;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  try {
    const WithDefaults options(config);
    const DriverOptions o(kWho, &options.config);
    auto parsed = parse(o);
    if (!parsed) return report(err, len, parsed.error());
    const std::string path = o.text("hidraw").value_or(d && d->devnode ? d->devnode : "");
    if (path.empty())
      return report(err, len, std::string(kWho) + ": no device: give hidraw = /dev/hidrawN",
                    PROCAM_EINVAL);
    auto transport = wm::HidrawWiimote::open(path);
    if (!transport)
      return report(err, len, std::string(kWho) + ": " + transport.error().message, PROCAM_ENODEV);
    return finish(std::move(*transport), *parsed, {}, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

}  // namespace

int createWiimoteOn(std::unique_ptr<wiimote::WiimoteTransport> transport,
                    const procam_config* config, wiimote::Clock clock, procam_device* out,
                    char* err, std::size_t len) {
  try {
    const WithDefaults options(config);
    const DriverOptions o(kWho, &options.config);
    auto parsed = parse(o);
    if (!parsed) return report(err, len, parsed.error());
    return finish(std::move(transport), *parsed, std::move(clock), out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const tracking::TrackedPose* wiimoteLastPose(const procam_device& device) {
  if (device.destroy != &destroy || !device.self) return nullptr;
  const auto& last = static_cast<const wm::WiimoteTracker*>(device.self)->lastPose();
  return last ? &*last : nullptr;
}

const procam_driver_factory kHidFactory = {
    PROCAM_FAMILY_TRACKER,
    "hid",
    "Wii Remote IR camera on /dev/hidrawN (057e:0306/0330): up to 4 IR LEDs, constellation "
    "pose, filter",
    &probe,
    &create,
    nullptr};

}  // namespace procam::tracker::plugin
