// The "replay" camera driver: ReplayCamera behind the plugin ABI.
#include <cstring>
#include <exception>

#include "camera/plugin/camera_device.hpp"
#include "camera/plugin/camera_plugin.hpp"
#include "camera/replay/replay_camera.hpp"

namespace procam::camera::plugin {
namespace {

// A recording is never found by udev: it is named in the configuration (driver
// "replay"), or described with subsystem "replay" / a REPLAY_DIR property.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_CAMERA) return 0;
  const bool replay = (d->subsystem && std::strcmp(d->subsystem, "replay") == 0) ||
                      !plugins::property(d, "REPLAY_DIR").empty();
  return replay ? 90 : 0;
}

Result<ReplayOptions> parse(const procam_device_desc* d, const CameraOptions& o) {
  if (auto ok = o.onlyKnown({"dir", "speed", "loop", "pixel", PROCAM_CAMERA_CONTROL_KEYS}); !ok)
    return tl::unexpected(ok.error());
  ReplayOptions r;
  if (auto dir = o.text("dir"))
    r.dir = *dir;
  else if (auto prop = plugins::property(d, "REPLAY_DIR"); !prop.empty())
    r.dir = prop;
  else if (d && d->devnode)
    r.dir = d->devnode;
  if (r.dir.empty())
    return fail(ErrorCode::kInvalidInput, "replay camera: no recording: give the option dir");
  auto speed = o.number("speed");
  auto loop = o.flag("loop");
  auto pixel = o.pixel();
  if (!speed) return tl::unexpected(speed.error());
  if (!loop) return tl::unexpected(loop.error());
  if (!pixel) return tl::unexpected(pixel.error());
  r.speed = speed->value_or(1.0);
  if (!(r.speed >= 0))
    return fail(ErrorCode::kInvalidInput,
                "replay camera: speed must be >= 0 (0: as fast as asked)");
  r.loop = loop->value_or(false);
  r.pixel = *pixel;
  return r;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  return createCamera<ReplayOptions>(
      "replay", d, config, out, err, len, &parse,
      [](ReplayOptions o) { return std::make_unique<ReplayCamera>(std::move(o)); });
}

}  // namespace

const procam_driver_factory kReplayFactory = {PROCAM_FAMILY_CAMERA,
                                              "replay",
                                              "recorded frames: a folder of images and index.csv",
                                              &probe,
                                              &create,
                                              nullptr};

}  // namespace procam::camera::plugin
