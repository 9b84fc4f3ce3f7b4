#include "camera/plugin/camera_device.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "camera/convert.hpp"

namespace procam::camera::plugin {

CameraOptions::CameraOptions(const std::string& driver, const procam_config* config)
    : options_(driver + " camera", config) {}

Result<void> CameraOptions::onlyKnown(std::initializer_list<const char*> known) const {
  return options_.onlyKnown(known);
}

Result<std::optional<double>> CameraOptions::number(const char* key) const {
  return options_.number(key);
}

Result<std::optional<bool>> CameraOptions::flag(const char* key) const {
  return options_.flag(key);
}

Result<std::optional<int>> CameraOptions::whole(const char* key, int lo, int hi) const {
  auto v = options_.integer(key);
  if (!v) return tl::unexpected(v.error());
  if (!*v) return std::optional<int>();
  if (**v < lo || **v > hi)
    return fail(ErrorCode::kInvalidInput, options_.who() + ": option " + key + ": " +
                                              std::to_string(**v) + " is not in " +
                                              std::to_string(lo) + ".." + std::to_string(hi));
  return std::optional<int>(int(**v));
}

Result<std::optional<procam_pixel_format>> CameraOptions::pixel() const {
  const auto t = text("pixel");
  if (!t) return std::optional<procam_pixel_format>();
  auto p = parsePixel(*t);
  if (!p)
    return fail(ErrorCode::kInvalidInput,
                options_.who() + ": option pixel: '" + *t + "' is not gray8, gray16 or rgb8");
  return p;
}

Result<void> applyControls(Camera& camera, const CameraOptions& o) {
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
      return report(err, len,
                    {ErrorCode::kInvalidInput, "exposure must be a positive number of seconds"});
    if (auto ok = cam(self)->setControl(Control::kAutoExposure, 0); !ok)
      return report(err, len, ok.error());
    if (auto ok = cam(self)->setControl(Control::kExposure, seconds); !ok)
      return report(err, len, ok.error());
    return PROCAM_OK;
  } catch (const std::exception& e) {
    return report(err, len, {ErrorCode::kInternal, e.what()});
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
    return report(err, len, {ErrorCode::kInternal, e.what()});
  }
}

int getSettings(void* self, procam_camera_settings* out) {
  try {
    Camera* c = cam(self);
    out->exposure_s = c->exposureSeconds().value_or(std::nan(""));
    out->gain = c->gain().value_or(std::nan(""));
    out->gain_db = c->gainInDb() ? 1 : 0;
    return PROCAM_OK;
  } catch (const std::exception&) {
    return PROCAM_EINTERNAL;
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

const procam_camera_ops kOps = {
    PROCAM_CAMERA_OPS_VERSION, &getFormat, &setExposure, &capture, nullptr, &getSettings};

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
    return report(err, len, {ErrorCode::kInternal, e.what()});
  }
}

}  // namespace procam::camera::plugin
