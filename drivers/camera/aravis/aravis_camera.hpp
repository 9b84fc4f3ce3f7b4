#pragma once
// The "aravis" camera: GigE Vision and USB3 Vision cameras through libaravis 0.8. Open by
// id (an IP address, "<vendor>-<serial>", a USB3 Vision id), region, pixel format, packet
// size (GigE), frame rate, a pool of stream buffers, exposure and gain in the camera's
// GenICam units. The frame of a Mono8/Mono16 stream points into the Aravis buffer, which
// goes back to the stream at the next capture.
#include <atomic>
#include <optional>
#include <string>

#include "camera/camera.hpp"
#include "camera/convert.hpp"

typedef struct _ArvCamera ArvCamera;
typedef struct _ArvStream ArvStream;
typedef struct _ArvBuffer ArvBuffer;

namespace procam::camera {

struct AravisOptions {
  std::string id;                  // as arv_camera_new() takes it
  uint32_t width = 0, height = 0;  // 0: the camera's current region
  std::string pixel_format;        // GenICam name ("Mono8", "Mono16", "RGB8Packed"); empty: keep
  int packet_size = 0;             // GigE packet size in bytes; 0: negotiated by Aravis
  double fps = 0;                  // 0: the camera's current rate
  unsigned buffers = 8;            // stream buffer pool, at least 2
  std::optional<procam_pixel_format> pixel;
};

class AravisCamera final : public Camera {
 public:
  explicit AravisCamera(AravisOptions options);
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  // Opens (or reopens, after a failure) the camera and starts continuous acquisition.
  CamResult<void> start() override;
  void stop() override;
  FrameFormat format() const override { return format_; }
  // kNoDevice with the reason when the camera stopped answering (control lost, or no
  // frame within the timeout and the camera no longer answers a register read).
  CamResult<const Frame*> capture(int timeout_ms) override;
  CamResult<void> setControl(Control control, double value) override;
  std::string name() const override { return "aravis " + options_.id; }

  // The camera's exposure time in seconds (read back), for checks.
  CamResult<double> exposure() const;
  // Buffers the stream dropped or completed badly since start.
  uint64_t failedFrames() const { return failed_; }

 private:
  CamResult<void> configure();
  CamResult<void> checkAlive() const;
  void releaseHeld();

  AravisOptions options_;
  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  ArvBuffer* held_ = nullptr;
  SourceFormat source_ = SourceFormat::kGrey;
  FrameFormat format_;
  mutable std::atomic<bool> lost_{false};
  uint64_t failed_ = 0;
  cv::Mat storage_;
  Frame frame_;
};

}  // namespace procam::camera
