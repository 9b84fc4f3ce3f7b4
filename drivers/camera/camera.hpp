#pragma once
// The camera interface every backend (replay, v4l2, aravis, libcamera) implements, the
// frame it delivers and its typed errors. A frame is in one of the pipeline's formats
// (8- or 16-bit mono, RGB8; rows top to bottom) with a CLOCK_MONOTONIC timestamp; the
// conversion from what the device sends happens once, in convert.hpp.
//
// Errors are procam::Result with ErrorCode's device codes (kNoDevice, kTimeout, kAgain,
// kNotSupported, kEnded), each one status of the plugin ABI, so a backend says exactly
// what went wrong: a control the device does not have is kNotSupported, never silently
// ignored.
#include <procamd/procam_plugin.h>

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>

#include "core/error.hpp"

namespace procam::camera {

// Image size and pipeline pixel format of the frames a camera delivers.
struct FrameFormat {
  uint32_t width = 0;
  uint32_t height = 0;
  procam_pixel_format pixel = PROCAM_PIXEL_GRAY8;
};

// One frame. `image` is CV_8UC1 (GRAY8), CV_16UC1 (GRAY16) or CV_8UC3 in RGB order; it
// may point into the driver's buffer and stays valid until the next capture or stop.
struct Frame {
  cv::Mat image;
  procam_pixel_format pixel = PROCAM_PIXEL_GRAY8;
  uint64_t timestamp_ns = 0;  // CLOCK_MONOTONIC
  uint64_t sequence = 0;      // the device's frame counter
  int copies = 0;             // times the pixels were copied since the device handed them over
};

// The controls structured light needs locked. Units: exposure in seconds, gain in the
// device's own unit (dB for GenICam, a register value for V4L2), white balance in
// kelvin, power-line frequency in Hz (0 = off, 50, 60).
enum class Control { kExposure, kAutoExposure, kGain, kWhiteBalance, kPowerLine };
const char* toString(Control control);

class Camera {
 public:
  virtual ~Camera() = default;
  // Opens the device and starts streaming in the negotiated format.
  virtual Result<void> start() = 0;
  virtual void stop() = 0;
  virtual FrameFormat format() const = 0;
  // The next frame, waiting at most `timeout_ms` (0: only one already waiting; kAgain
  // when there is none). kNoDevice when the device went away.
  virtual Result<const Frame*> capture(int timeout_ms) = 0;
  // kNotSupported naming the control when the device does not have it. kAutoExposure
  // takes 0 (manual) or 1 (automatic).
  virtual Result<void> setControl(Control control, double value) = 0;
  // The exposure (seconds) and gain (the `gain` option's unit) in effect, read from
  // the device; nullopt where it cannot tell.
  virtual std::optional<double> exposureSeconds() { return std::nullopt; }
  virtual std::optional<double> gain() { return std::nullopt; }
  virtual bool gainInDb() const { return false; }
  // A descriptor that becomes readable when a frame is waiting, or -1.
  virtual int pollFd() const { return -1; }
  virtual std::string name() const = 0;
};

// "not supported by this device" for a control, with the device's name.
tl::unexpected<Error> unsupported(const std::string& device, Control control);

// Monotonic clock now, in nanoseconds.
uint64_t monotonicNs();

}  // namespace procam::camera
