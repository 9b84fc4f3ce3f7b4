#pragma once
// The "libcamera" camera: CameraManager, one stream configured for the asked size and
// format, a ring of requests over buffers from a FrameBufferAllocator, and manual
// exposure and gain through request controls. Completed requests arrive on libcamera's
// thread and are handed over through a queue and an eventfd (the poll fd).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "camera/convert.hpp"

namespace procam::camera {

struct LibcameraOptions {
  std::string id;                  // libcamera's camera id; empty: the first camera
  uint32_t width = 0, height = 0;  // 0: the configuration libcamera proposes
  std::string format;              // "R8", "YUYV", "MJPEG", "RGB888", "BGR888"; empty: proposed
  unsigned buffers = 4;
  std::optional<procam_pixel_format> pixel;
};

// The ids of the cameras libcamera finds; kIo when its CameraManager does not start.
Result<std::vector<std::string>> libcameraCameraIds();

class LibcameraCamera final : public Camera {
 public:
  explicit LibcameraCamera(LibcameraOptions options);
  ~LibcameraCamera() override;
  LibcameraCamera(const LibcameraCamera&) = delete;
  LibcameraCamera& operator=(const LibcameraCamera&) = delete;

  // kNoDevice "no camera" when libcamera lists none (or not the one asked for).
  Result<void> start() override;
  void stop() override;
  FrameFormat format() const override;
  Result<const Frame*> capture(int timeout_ms) override;
  // Applied to the requests queued from now on. Gain is libcamera's analogue gain
  // (a multiplier, not dB); white balance is ColourTemperature with AWB off.
  Result<void> setControl(Control control, double value) override;
  // From the metadata of the last frame captured (ExposureTime, AnalogueGain).
  std::optional<double> exposureSeconds() override;
  std::optional<double> gain() override;
  int pollFd() const override;
  std::string name() const override { return "libcamera " + options_.id; }

 private:
  struct State;
  LibcameraOptions options_;
  std::unique_ptr<State> s_;
};

}  // namespace procam::camera
