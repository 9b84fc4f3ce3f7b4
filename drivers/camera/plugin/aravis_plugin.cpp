// The "aravis" camera driver: AravisCamera behind the plugin ABI.
#include <cmath>
#include <cstring>
#include <exception>

#include "camera/aravis/aravis_camera.hpp"
#include "camera/plugin/camera_device.hpp"
#include "camera/plugin/camera_plugin.hpp"

namespace procam::camera::plugin {
namespace {

// GigE Vision cameras are not udev devices: they are configured (driver "aravis", or
// an ARAVIS_ID property). USB3 Vision cameras are: interface class EF/05/00.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_CAMERA) return 0;
  if ((d->subsystem && std::strcmp(d->subsystem, "aravis") == 0) ||
      !plugins::property(d, "ARAVIS_ID").empty())
    return 60;
  return plugins::property(d, "ID_USB_INTERFACES").find(":ef0500:") != std::string::npos ? 60 : 0;
}

Result<AravisOptions> parse(const procam_device_desc* d, const CameraOptions& o) {
  if (auto ok = o.onlyKnown({"id", "width", "height", "pixel_format", "packet_size", "fps",
                             "buffers", "pixel", PROCAM_CAMERA_CONTROL_KEYS});
      !ok)
    return tl::unexpected(ok.error());
  AravisOptions a;
  if (auto id = o.text("id"))
    a.id = *id;
  else if (auto prop = plugins::property(d, "ARAVIS_ID"); !prop.empty())
    a.id = prop;
  else if (d && d->name)
    a.id = d->name;
  if (a.id.empty())
    return fail(ErrorCode::kInvalidInput, "aravis camera: no camera id: give the option id");
  auto w = o.whole("width", 1, 65535);
  auto h = o.whole("height", 1, 65535);
  auto packet = o.whole("packet_size", 576, 65535);
  auto buffers = o.whole("buffers", 2, 256);
  auto fps = o.number("fps");
  auto pixel = o.pixel();
  for (auto* r : {&w, &h, &packet, &buffers})
    if (!*r) return tl::unexpected(r->error());
  if (!fps) return tl::unexpected(fps.error());
  if (!pixel) return tl::unexpected(pixel.error());
  if (w->has_value() != h->has_value())
    return fail(ErrorCode::kInvalidInput, "aravis camera: give both width and height, or neither");
  a.width = uint32_t(w->value_or(0));
  a.height = uint32_t(h->value_or(0));
  a.packet_size = packet->value_or(0);
  a.buffers = unsigned(buffers->value_or(8));
  a.fps = fps->value_or(0);
  a.pixel_format = o.text("pixel_format").value_or("");
  a.pixel = *pixel;
  return a;
}

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  return createCamera<AravisOptions>(
      "aravis", d, config, out, err, len, &parse,
      [](AravisOptions o) { return std::make_unique<AravisCamera>(std::move(o)); });
}

}  // namespace

const procam_driver_factory kAravisFactory = {PROCAM_FAMILY_CAMERA,
                                              "aravis",
                                              "GigE Vision / USB3 Vision camera (libaravis)",
                                              &probe,
                                              &create,
                                              nullptr};

}  // namespace procam::camera::plugin
