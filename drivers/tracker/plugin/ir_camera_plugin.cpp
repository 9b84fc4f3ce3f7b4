// The "ir_camera" tracker driver: IrCameraTracker behind the plugin ABI, on a camera
// created through the camera drivers' own plugin table (any of them, by name).
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "camera/plugin/camera_plugin.hpp"
#include "tracker/ir_camera/ir_camera_tracker.hpp"
#include "tracker/plugin/led_tracker_options.hpp"
#include "tracker/plugin/tracker_plugin.hpp"

namespace procam::tracker::plugin {
namespace {

using plugins::DriverOptions;
using plugins::property;
using plugins::report;

constexpr const char* kWho = "ir_camera tracker";
constexpr const char* kCameraPrefix = "camera.";  // options passed to the camera driver
constexpr int kDefaultMaxBlobs = 8;

bool isVideo(const procam_device_desc* d) {
  return (d->subsystem && std::strcmp(d->subsystem, "video4linux") == 0) ||
         plugins::startsWith(d->devnode, "/dev/video");
}

// A V4L2 node that a udev rule gave PROCAM_ROLE=tracker (an IR camera watching the
// viewer); any other camera is used when the driver is named in the configuration.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_TRACKER || property(d, "PROCAM_ROLE") != "tracker") return 0;
  return isVideo(d) ? 50 : 0;
}

int readPose(void* self, procam_pose_sample* out, char* err, std::size_t len) {
  try {
    auto s = static_cast<IrCameraTracker*>(self)->read();
    if (!s) return report(err, len, s.error());
    *out = *s;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

const procam_tracker_ops kOps = {PROCAM_TRACKER_OPS_VERSION, &readPose, nullptr};

int pollFd(void* self) {
  return static_cast<IrCameraTracker*>(self)->pollFd();
}

void destroy(void* self) {
  delete static_cast<IrCameraTracker*>(self);
}

const procam_driver_factory* cameraFactory(const std::string& name, std::string& known) {
  const procam_plugin_table* table = procam_camera_plugin_entry();
  for (std::size_t i = 0; i < table->n_factories; ++i) {
    const procam_driver_factory& f = table->factories[i];
    known += (known.empty() ? "" : ", ") + std::string(f.name);
    if (name == f.name) return &f;
  }
  return nullptr;
}

// The options split in the tracker's own and the camera's (prefix removed); `text` keeps
// the strings alive.
struct SplitOptions {
  std::vector<std::pair<std::string, std::string>> text;
  std::vector<procam_kv> own, camera;
  procam_config own_config{}, camera_config{};

  explicit SplitOptions(const procam_config* config) {
    const std::size_t n = config ? config->n_options : 0;
    for (std::size_t i = 0; i < n; ++i) {
      const procam_kv& kv = config->options[i];
      if (kv.key && kv.value) text.emplace_back(kv.key, kv.value);
    }
    const std::size_t prefix = std::strlen(kCameraPrefix);
    for (const auto& [k, v] : text) {
      if (k.compare(0, prefix, kCameraPrefix) == 0)
        camera.push_back({k.c_str() + prefix, v.c_str()});
      else
        own.push_back({k.c_str(), v.c_str()});
    }
    own_config = {own.data(), own.size()};
    camera_config = {camera.data(), camera.size()};
  }
};

#define PROCAM_IR_CAMERA_KEYS                                                                  \
  "camera_driver", "camera_device", "capture_timeout_ms", "threshold", "min_area", "max_area", \
      "max_elongation", "max_blobs", PROCAM_TRACKER_CAMERA_KEYS, PROCAM_LED_TRACKER_KEYS

Result<IrCameraConfig> parse(const DriverOptions& o) {
  if (auto ok = o.onlyKnown({PROCAM_IR_CAMERA_KEYS}); !ok)
    return fail(ErrorCode::kInvalidInput,
                ok.error().message + "; the camera's options take the prefix camera.");
  IrCameraConfig c;
  auto cam = trackerCamera(o);
  if (!cam) return tl::unexpected(cam.error());
  c.K = cam->K;
  c.dist = cam->dist;
  c.pose = cam->pose;
  auto tracker = ledTrackerOptions(o);
  if (!tracker) return tl::unexpected(tracker.error());
  c.tracker = std::move(*tracker);
  auto threshold = o.number("threshold");
  auto elongation = o.number("max_elongation");
  if (!threshold) return tl::unexpected(threshold.error());
  if (!elongation) return tl::unexpected(elongation.error());
  c.blobs.threshold = threshold->value_or(c.blobs.threshold);
  c.blobs.max_elongation = elongation->value_or(c.blobs.max_elongation);
  // The strongest 8: a frame without a previous pose searches C(LEDs, 4) x P(blobs, 4)
  // hypotheses, ~0.1 s for 5 LEDs and 8 blobs, seconds for 15 (README.md, bench).
  c.blobs.max_blobs = kDefaultMaxBlobs;
  for (auto [key, value] :
       {std::pair{"min_area", &c.blobs.min_area}, std::pair{"max_area", &c.blobs.max_area},
        std::pair{"max_blobs", &c.blobs.max_blobs},
        std::pair{"capture_timeout_ms", &c.capture_timeout_ms}}) {
    auto v = o.integer(key);
    if (!v) return tl::unexpected(v.error());
    if (*v && (**v < 0 || **v > 1'000'000))
      return fail(ErrorCode::kInvalidInput, o.who() + ": option " + key + " must be 0..1000000");
    if (*v) *value = static_cast<int>(**v);
  }
  return c;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  try {
    const SplitOptions split(config);
    const DriverOptions o(kWho, &split.own_config);
    auto parsed = parse(o);
    if (!parsed) return report(err, len, parsed.error());

    std::string driver;
    if (auto name = o.text("camera_driver"))
      driver = *name;
    else if (d && isVideo(d))
      driver = "v4l2";
    std::string known;
    const procam_driver_factory* factory = cameraFactory(driver, known);
    if (driver.empty())
      return report(err, len,
                    std::string(kWho) + ": option camera_driver is needed (" + known + ")",
                    PROCAM_EINVAL);
    if (!factory)
      return report(err, len,
                    std::string(kWho) + ": unknown camera_driver '" + driver + "' (" + known + ")",
                    PROCAM_EINVAL);

    // The camera is described as the tracker's device, in the camera family.
    procam_device_desc camera_desc{};
    std::vector<procam_kv> properties;
    const std::string device = o.text("camera_device").value_or(d && d->devnode ? d->devnode : "");
    if (d) {
      camera_desc = *d;
      for (std::size_t i = 0; i < d->n_properties; ++i)
        if (d->properties[i].key && std::strcmp(d->properties[i].key, "PROCAM_ROLE") != 0)
          properties.push_back(d->properties[i]);
    }
    properties.push_back({"PROCAM_ROLE", "camera"});
    camera_desc.family = PROCAM_FAMILY_CAMERA;
    camera_desc.devnode = device.empty() ? nullptr : device.c_str();
    camera_desc.properties = properties.data();
    camera_desc.n_properties = properties.size();

    procam_device camera{};
    std::string reason(256, '\0');
    const int rc = factory->create(&camera_desc, &split.camera_config, &camera, reason.data(),
                                   reason.size() - 1);
    if (rc != PROCAM_OK)
      return report(err, len,
                    std::string(kWho) + ": camera driver '" + driver + "': " + reason.c_str(), rc);
    auto tracker = IrCameraTracker::create(OwnedCamera(camera), *parsed);
    if (!tracker) return report(err, len, tracker.error());
    *out = {};
    out->family = PROCAM_FAMILY_TRACKER;
    out->self = new IrCameraTracker(std::move(*tracker));
    out->poll_fd = &pollFd;
    out->destroy = &destroy;
    out->ops.tracker = &kOps;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, e.what(), PROCAM_EINTERNAL);
  }
}

}  // namespace

const tracking::TrackedPose* irCameraLastPose(const procam_device& device) {
  if (device.destroy != &destroy || !device.self) return nullptr;
  const auto& last = static_cast<const IrCameraTracker*>(device.self)->lastPose();
  return last ? &*last : nullptr;
}

const procam_driver_factory kIrCameraFactory = {
    PROCAM_FAMILY_TRACKER,
    "ir_camera",
    "IR LEDs on the viewer seen by a camera (any camera driver): blobs, constellation pose, "
    "filter",
    &probe,
    &create,
    nullptr};

}  // namespace procam::tracker::plugin
