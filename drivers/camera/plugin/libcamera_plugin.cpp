// The "libcamera" camera driver: LibcameraCamera behind the plugin ABI.
#include <cstring>
#include <exception>

#include "camera/libcamera/libcamera_camera.hpp"
#include "camera/plugin/camera_device.hpp"
#include "camera/plugin/camera_plugin.hpp"

namespace procam::camera::plugin {
namespace {

// libcamera drives the same V4L2 nodes as the v4l2 driver (and the ISP pipelines it
// cannot): named in the configuration, or a device with a LIBCAMERA_ID property.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_CAMERA) return 0;
  if ((d->subsystem && std::strcmp(d->subsystem, "libcamera") == 0) ||
      !plugins::property(d, "LIBCAMERA_ID").empty())
    return 60;
  return 0;
}

Result<LibcameraOptions> parse(const procam_device_desc* d, const CameraOptions& o) {
  if (auto ok = o.onlyKnown(
          {"id", "width", "height", "format", "buffers", "pixel", PROCAM_CAMERA_CONTROL_KEYS});
      !ok)
    return tl::unexpected(ok.error());
  LibcameraOptions l;
  if (auto id = o.text("id"))
    l.id = *id;
  else
    l.id = plugins::property(d, "LIBCAMERA_ID");
  auto w = o.whole("width", 1, 65535);
  auto h = o.whole("height", 1, 65535);
  auto n = o.whole("buffers", 2, 64);
  auto pixel = o.pixel();
  for (auto* r : {&w, &h, &n})
    if (!*r) return tl::unexpected(r->error());
  if (!pixel) return tl::unexpected(pixel.error());
  if (w->has_value() != h->has_value())
    return fail(ErrorCode::kInvalidInput,
                "libcamera camera: give both width and height, or neither");
  l.width = uint32_t(w->value_or(0));
  l.height = uint32_t(h->value_or(0));
  l.buffers = unsigned(n->value_or(4));
  l.format = o.text("format").value_or("");
  l.pixel = *pixel;
  return l;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  return createCamera<LibcameraOptions>(
      "libcamera", d, config, out, err, len, &parse,
      [](LibcameraOptions o) { return std::make_unique<LibcameraCamera>(std::move(o)); });
}

}  // namespace

const procam_driver_factory kLibcameraFactory = {PROCAM_FAMILY_CAMERA,
                                                 "libcamera",
                                                 "camera through libcamera's CameraManager",
                                                 &probe,
                                                 &create,
                                                 nullptr};

}  // namespace procam::camera::plugin
