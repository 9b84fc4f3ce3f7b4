// The "v4l2" camera driver: V4l2Camera behind the plugin ABI.
#include <cmath>
#include <cstring>
#include <exception>

#include "camera/plugin/camera_device.hpp"
#include "camera/plugin/camera_plugin.hpp"
#include "camera/v4l2/v4l2_camera.hpp"

namespace procam::camera::plugin {
namespace {

// udev (70-procamd.rules) tags V4L2 capture nodes PROCAM_ROLE=camera.
int probe(const procam_device_desc* d) {
  if (!d || d->family != PROCAM_FAMILY_CAMERA || plugins::property(d, "PROCAM_ROLE") != "camera")
    return 0;
  const bool v4l2 = (d->subsystem && std::strcmp(d->subsystem, "video4linux") == 0) ||
                    (d->devnode && std::strncmp(d->devnode, "/dev/video", 10) == 0);
  return v4l2 ? 50 : 0;
}

Result<V4l2Options> parse(const procam_device_desc* d, const CameraOptions& o) {
  if (auto ok = o.onlyKnown({"device", "width", "height", "format", "fps", "buffers", "pixel",
                             PROCAM_CAMERA_CONTROL_KEYS});
      !ok)
    return tl::unexpected(ok.error());
  V4l2Options v;
  v.device = o.text("device").value_or(d && d->devnode ? d->devnode : "");
  if (v.device.empty())
    return fail(ErrorCode::kInvalidInput, "v4l2 camera: no device node: give the option device");
  auto w = o.whole("width", 1, 65535);
  auto h = o.whole("height", 1, 65535);
  auto n = o.whole("buffers", 4, 64);
  auto fps = o.number("fps");
  auto pixel = o.pixel();
  for (auto* r : {&w, &h, &n})
    if (!*r) return tl::unexpected(r->error());
  if (!fps) return tl::unexpected(fps.error());
  if (!pixel) return tl::unexpected(pixel.error());
  if (w->has_value() != h->has_value())
    return fail(ErrorCode::kInvalidInput, "v4l2 camera: give both width and height, or neither");
  v.width = uint32_t(w->value_or(0));
  v.height = uint32_t(h->value_or(0));
  v.buffers = unsigned(n->value_or(4));
  v.fps = fps->value_or(0);
  if (v.fps < 0) return fail(ErrorCode::kInvalidInput, "v4l2 camera: fps must be > 0");
  v.pixel = *pixel;
  if (auto f = o.text("format")) {
    v.fourcc = parseFourcc(*f);
    if (!v.fourcc)
      return fail(ErrorCode::kInvalidInput,
                  "v4l2 camera: option format: '" + *f +
                      "' is not one of GREY, Y16, YUYV, MJPG, RGB3, BGR3");
  }
  return v;
}

}  // namespace

int createV4l2On(std::unique_ptr<V4l2Io> io, const procam_device_desc* d,
                 const procam_config* config, procam_device* out, char* err, std::size_t len) {
  return createCamera<V4l2Options>(
      "v4l2", d, config, out, err, len, &parse, [&io](V4l2Options o) -> std::unique_ptr<Camera> {
        return std::make_unique<V4l2Camera>(std::move(o), std::move(io));
      });
}

namespace {

int create(const procam_device_desc* d, const procam_config* config, procam_device* out, char* err,
           std::size_t len) {
  return createV4l2On(systemV4l2Io(), d, config, out, err, len);
}

}  // namespace

const procam_driver_factory kV4l2Factory = {PROCAM_FAMILY_CAMERA,
                                            "v4l2",
                                            "Video4Linux2 capture device (mmap streaming)",
                                            &probe,
                                            &create,
                                            nullptr};

}  // namespace procam::camera::plugin
