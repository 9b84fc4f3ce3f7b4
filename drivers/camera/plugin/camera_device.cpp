#include "camera/plugin/camera_device.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "camera/convert.hpp"

namespace procam::camera::plugin {

int report(char* err, std::size_t len, const CameraError& error) {
  if (err && len > 0) std::snprintf(err, len, "%s", error.message.c_str());
  return int(error.status);
}

CameraOptions::CameraOptions(std::string driver, const procam_config* config)
    : driver_(std::move(driver)), config_(config) {}

CamResult<void> CameraOptions::onlyKnown(std::initializer_list<const char*> known) const {
  for (std::size_t i = 0; config_ && i < config_->n_options; ++i) {
    const char* key = config_->options[i].key;
    bool ok = false;
    for (const char* k : known) ok = ok || (key && std::strcmp(key, k) == 0);
    if (ok) continue;
    std::string list;
    for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    return camFail(Status::kInvalid, driver_ + " camera: unknown option '" +
                                         (key ? key : "(null)") + "' (known: " + list + ")");
  }
  return {};
}

std::optional<std::string> CameraOptions::text(const char* key) const {
  std::optional<std::string> value;
  for (std::size_t i = 0; config_ && i < config_->n_options; ++i) {
    const procam_kv& kv = config_->options[i];
    if (kv.key && kv.value && std::strcmp(kv.key, key) == 0) value = kv.value;
  }
  return value;
}

CamResult<void> CameraOptions::bad(const char* key, const std::string& value,
                                   const char* what) const {
  return camFail(Status::kInvalid,
                 driver_ + " camera: option " + key + ": '" + value + "' is not " + what);
}

CamResult<std::optional<double>> CameraOptions::number(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<double>();
  char* end = nullptr;
  const double v = std::strtod(t->c_str(), &end);
  if (t->empty() || *end != '\0' || !std::isfinite(v))
    return tl::unexpected(bad(key, *t, "a number").error());
  return std::optional<double>(v);
}

CamResult<std::optional<int>> CameraOptions::whole(const char* key, int lo, int hi) const {
  auto v = number(key);
  if (!v) return tl::unexpected(v.error());
  if (!*v) return std::optional<int>();
  if (**v < lo || **v > hi || std::floor(**v) != **v)
    return tl::unexpected(
        bad(key, *text(key),
            ("a whole number " + std::to_string(lo) + ".." + std::to_string(hi)).c_str())
            .error());
  return std::optional<int>(int(**v));
}

CamResult<std::optional<bool>> CameraOptions::flag(const char* key) const {
  const auto t = text(key);
  if (!t) return std::optional<bool>();
  if (*t == "true" || *t == "1" || *t == "yes") return std::optional<bool>(true);
  if (*t == "false" || *t == "0" || *t == "no") return std::optional<bool>(false);
  return tl::unexpected(bad(key, *t, "true or false").error());
}

CamResult<std::optional<procam_pixel_format>> CameraOptions::pixel() const {
  const auto t = text("pixel");
  if (!t) return std::optional<procam_pixel_format>();
  auto p = parsePixel(*t);
  if (!p) return tl::unexpected(bad("pixel", *t, "gray8, gray16 or rgb8").error());
  return p;
}

CamResult<void> applyControls(Camera& camera, const CameraOptions& o) {
  // Auto exposure first: a manual exposure on a camera still in auto would be overridden.
  auto autoExposure = o.flag("auto_exposure");
  if (!autoExposure) return tl::unexpected(autoExposure.error());
  if (*autoExposure) {
    if (auto ok = camera.setControl(Control::kAutoExposure, **autoExposure ? 1 : 0); !ok) return ok;
  }
  const std::pair<const char*, Control> numeric[] = {{"exposure_s", Control::kExposure},
                                                     {"gain", Control::kGain},
                                                     {"white_balance_k", Control::kWhiteBalance},
                                                     {"power_line_hz", Control::kPowerLine}};
  for (const auto& [key, control] : numeric) {
    auto v = o.number(key);
    if (!v) return tl::unexpected(v.error());
    if (!*v) continue;
    if (control == Control::kExposure && !*autoExposure) {
      if (auto ok = camera.setControl(Control::kAutoExposure, 0); !ok) return ok;
    }
    if (auto ok = camera.setControl(control, **v); !ok) return ok;
  }
  return {};
}

std::string descProperty(const procam_device_desc* d, const char* key) {
  for (std::size_t i = 0; d && i < d->n_properties; ++i) {
    const procam_kv& kv = d->properties[i];
    if (kv.key && kv.value && std::strcmp(kv.key, key) == 0) return kv.value;
  }
  return {};
}

namespace {

Camera* cam(void* self) {
  return static_cast<Camera*>(self);
}

int getFormat(void* self, uint32_t* w, uint32_t* h, procam_pixel_format* f) {
  try {
    const FrameFormat ff = cam(self)->format();
    *w = ff.width;
    *h = ff.height;
    *f = ff.pixel;
    return PROCAM_OK;
  } catch (const std::exception&) {
    return PROCAM_EINTERNAL;
  }
}

int setExposure(void* self, double seconds, char* err, std::size_t len) {
  try {
    if (!(seconds > 0) || !std::isfinite(seconds))
      return report(err, len, {Status::kInvalid, "exposure must be a positive number of seconds"});
    if (auto ok = cam(self)->setControl(Control::kAutoExposure, 0); !ok)
      return report(err, len, ok.error());
    if (auto ok = cam(self)->setControl(Control::kExposure, seconds); !ok)
      return report(err, len, ok.error());
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, {Status::kInternal, e.what()});
  }
}

int capture(void* self, int timeout_ms, procam_image* out, char* err, std::size_t len) {
  try {
    auto frame = cam(self)->capture(timeout_ms);
    if (!frame) return report(err, len, frame.error());
    const cv::Mat& m = (*frame)->image;
    out->width = uint32_t(m.cols);
    out->height = uint32_t(m.rows);
    out->stride = uint32_t(m.step[0]);
    out->format = (*frame)->pixel;
    out->data = m.data;
    out->timestamp_ns = (*frame)->timestamp_ns;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, {Status::kInternal, e.what()});
  }
}

int pollFd(void* self) {
  return cam(self)->pollFd();
}

void destroy(void* self) {
  Camera* c = cam(self);
  c->stop();
  delete c;
}

const procam_camera_ops kOps = {&getFormat, &setExposure, &capture};

}  // namespace

int finishCameraDevice(std::unique_ptr<Camera> camera, const CameraOptions& options,
                       procam_device* out, char* err, std::size_t len) {
  try {
    if (auto ok = camera->start(); !ok) return report(err, len, ok.error());
    if (auto ok = applyControls(*camera, options); !ok) {
      camera->stop();
      return report(err, len, ok.error());
    }
    out->family = PROCAM_FAMILY_CAMERA;
    out->self = camera.release();
    out->poll_fd = &pollFd;
    out->destroy = &destroy;
    out->ops.camera = &kOps;
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, {Status::kInternal, e.what()});
  }
}

}  // namespace procam::camera::plugin
