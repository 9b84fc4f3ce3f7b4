#pragma once
// What every camera driver of the plugin ABI shares: its text options, the controls
// any camera takes from its configuration, and the device wrapper that puts a started
// Camera behind procam_camera_ops. Nothing here throws.
#include <procamd/procam_plugin.h>

#include <exception>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>

#include "camera/camera.hpp"
#include "support/driver_support.hpp"

namespace procam::camera::plugin {

// Writes the message into the caller's buffer and returns the error's status.
using plugins::report;

// A driver's options (plugins/support's DriverOptions, "<driver> camera: option K: ..."),
// with the keys only cameras have.
class CameraOptions {
 public:
  CameraOptions(const std::string& driver, const procam_config* config);
  // kInvalid naming the first key not in `known`.
  Result<void> onlyKnown(std::initializer_list<const char*> known) const;
  std::optional<std::string> text(const char* key) const { return options_.text(key); }
  Result<std::optional<double>> number(const char* key) const;              // finite
  Result<std::optional<int>> whole(const char* key, int lo, int hi) const;  // lo..hi
  Result<std::optional<bool>> flag(const char* key) const;                  // true/false/1/0/yes/no
  // "gray8" / "gray16" / "rgb8" under key "pixel".
  Result<std::optional<procam_pixel_format>> pixel() const;

 private:
  plugins::DriverOptions options_;
};

// The control keys every camera driver accepts (README.md): exposure_s, auto_exposure,
// gain, white_balance_k, power_line_hz.
#define PROCAM_CAMERA_CONTROL_KEYS \
  "exposure_s", "auto_exposure", "gain", "white_balance_k", "power_line_hz"

// Sets the configured controls on a started camera; a control the device does not
// have fails with kNotSupported (the device is not opened half-configured).
Result<void> applyControls(Camera& camera, const CameraOptions& options);

// Starts `camera`, applies the configured controls and fills `out`. capture() maps
// to Camera::capture; set_exposure turns auto exposure off first.
int finishCameraDevice(std::unique_ptr<Camera> camera, const CameraOptions& options,
                       procam_device* out, char* err, std::size_t len);

// A driver's create(): options parsed by `parse`, the camera made by `make`, then
// finishCameraDevice(). Every error becomes a status and a reason; nothing throws.
template <class Options>
int createCamera(const char* driver, const procam_device_desc* d, const procam_config* config,
                 procam_device* out, char* err, std::size_t len,
                 Result<Options> (*parse)(const procam_device_desc*, const CameraOptions&),
                 const std::function<std::unique_ptr<Camera>(Options)>& make) {
  try {
    const CameraOptions o(driver, config);
    auto parsed = parse(d, o);
    if (!parsed) return report(err, len, parsed.error());
    return finishCameraDevice(make(std::move(*parsed)), o, out, err, len);
  } catch (const std::exception& e) {
    return report(err, len, {ErrorCode::kInternal, e.what()});
  }
}

}  // namespace procam::camera::plugin
