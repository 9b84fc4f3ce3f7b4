#pragma once
// The "aravis" camera: GigE Vision and USB3 Vision cameras through libaravis 0.8. Open by
// id (an IP address, "<vendor>-<serial>", a USB3 Vision id), region, pixel format, packet
// size (GigE), frame rate, a pool of stream buffers, exposure and gain in the camera's
// GenICam units. The frame of a Mono8/Mono16 stream points into the Aravis buffer, which
// goes back to the stream at the next capture.
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "camera/camera.hpp"
#include "camera/convert.hpp"

typedef struct _ArvCamera ArvCamera;
typedef struct _ArvStream ArvStream;
typedef struct _ArvBuffer ArvBuffer;

namespace procam::camera {

// An eventfd, closed with its owner.
class EventFd {
 public:
  EventFd();
  ~EventFd();
  EventFd(const EventFd&) = delete;
  EventFd& operator=(const EventFd&) = delete;
  int fd() const { return fd_; }
  void signal() const;  // async-signal- and thread-safe: a write(2)
  void drain() const;

 private:
  int fd_ = -1;
};

struct AravisOptions {
  std::string id;                  // as arv_camera_new() takes it
  uint32_t width = 0, height = 0;  // 0: the camera's current region
  std::string pixel_format;        // GenICam name ("Mono8", "Mono16", "RGB8Packed"); empty: keep
  int packet_size = 0;             // GigE packet size in bytes; 0: negotiated by Aravis
  double fps = 0;                  // 0: the camera's current rate
  unsigned buffers = 8;            // stream buffer pool, at least 2
  std::optional<procam_pixel_format> pixel;
  // How often a register of the camera is read to tell whether it still
  // answers (see watch()).
  unsigned probe_ms = 100;
};

class AravisCamera final : public Camera {
 public:
  explicit AravisCamera(AravisOptions options);
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  // Opens (or reopens, after a failure) the camera and starts continuous acquisition.
  Result<void> start() override;
  void stop() override;
  FrameFormat format() const override { return format_; }
  // kNoDevice with the reason when the camera stopped answering (control lost, or no
  // frame within the timeout and the camera no longer answers a register read).
  Result<const Frame*> capture(int timeout_ms) override;
  Result<void> setControl(Control control, double value) override;
  std::string name() const override { return "aravis " + options_.id; }
  // Readable once the camera is gone (control lost or a register read not
  // answered): the next capture() then returns kNoDevice. No frame makes it
  // readable, so a reader that only waits on it is woken for the loss alone.
  int pollFd() const override { return gone_fd_.fd(); }

  // The camera's exposure time in seconds (read back), for checks.
  Result<double> exposure() const;
  std::optional<double> exposureSeconds() override;
  // GenICam Gain, dB.
  std::optional<double> gain() override;
  bool gainInDb() const override { return true; }
  // Buffers the stream dropped or completed badly since start.
  uint64_t failedFrames() const { return failed_; }

 private:
  Result<void> configure();
  Result<void> checkAlive() const;
  void releaseHeld();
  void markGone() const;
  // The watchdog thread: reads a bootstrap register every probe_ms until one
  // goes unanswered (Aravis gives up after its retries, ~2.5 s on loopback),
  // then marks the camera gone. Aravis' own heartbeat reports control-lost
  // only after ~6-8 s; this keeps the loss of an idle camera within ~3 s.
  void watch();
  void startWatchdog();
  void stopWatchdog();
  static void onControlLost(void* device, void* self);

  AravisOptions options_;
  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  ArvBuffer* held_ = nullptr;
  SourceFormat source_ = SourceFormat::kGrey;
  FrameFormat format_;
  mutable std::atomic<bool> lost_{false};
  EventFd gone_fd_;
  unsigned long control_lost_handler_ = 0;
  std::thread watchdog_;
  mutable std::mutex watchdog_mutex_;
  std::condition_variable watchdog_wake_;
  bool watchdog_stop_ = false;
  mutable std::string gone_reason_;  // guarded by watchdog_mutex_
  uint64_t failed_ = 0;
  cv::Mat storage_;
  Frame frame_;
};

}  // namespace procam::camera
