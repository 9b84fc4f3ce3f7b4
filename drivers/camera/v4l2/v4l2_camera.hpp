#pragma once
// The "v4l2" camera: capability query, format negotiation (ENUM_FMT, ENUM_FRAMESIZES,
// S_FMT), frame rate (S_PARM), mmap streaming with >= 4 buffers, poll with a timeout, and
// the controls structured light locks. Every kernel call goes through V4l2Io.
#include <linux/videodev2.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "camera/convert.hpp"
#include "camera/v4l2/v4l2_io.hpp"

namespace procam::camera {

struct V4l2Options {
  std::string device;              // /dev/videoN, or a stable /dev/v4l/by-id|by-path link
  uint32_t width = 0, height = 0;  // 0: the largest size the format offers
  std::optional<uint32_t> fourcc;  // default: the first of kV4l2Preference the device has
  double fps = 0;                  // 0: the device's current rate
  unsigned buffers = 4;            // mmap buffers, at least 4
  std::optional<procam_pixel_format> pixel;
};

// Uncompressed formats first, mono before colour: no decode, least conversion.
inline constexpr uint32_t kV4l2Preference[] = {V4L2_PIX_FMT_GREY,  V4L2_PIX_FMT_Y16,
                                               V4L2_PIX_FMT_YUYV,  V4L2_PIX_FMT_RGB24,
                                               V4L2_PIX_FMT_BGR24, V4L2_PIX_FMT_MJPEG};
std::optional<SourceFormat> sourceFormatOf(uint32_t fourcc);
// "YUYV", "MJPG", "GREY", "Y16" (padded with spaces) -> fourcc.
std::optional<uint32_t> parseFourcc(const std::string& text);
std::string fourccText(uint32_t fourcc);

struct V4l2Info {
  std::string devnode, driver, card, bus_info;
};

// The capture devices (capture + streaming) among `dev_dir`/video*; nodes that do not
// open or answer QUERYCAP are left out. No devices: an empty list, not an error.
std::vector<V4l2Info> enumerateV4l2(V4l2Io& io, const std::string& dev_dir = "/dev");

class V4l2Camera final : public Camera {
 public:
  V4l2Camera(V4l2Options options, std::unique_ptr<V4l2Io> io);
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  Result<void> start() override;
  void stop() override;
  FrameFormat format() const override { return format_; }
  // Queues the previous frame's buffer again, then dequeues the next one; the frame
  // points into the mapped buffer when no conversion is needed.
  Result<const Frame*> capture(int timeout_ms) override;
  Result<void> setControl(Control control, double value) override;
  // V4L2_CID_EXPOSURE_ABSOLUTE (100 us units) and V4L2_CID_GAIN (the device's unit).
  std::optional<double> exposureSeconds() override;
  std::optional<double> gain() override;
  int pollFd() const override { return fd_; }
  std::string name() const override { return "v4l2 " + options_.device; }

  const V4l2Info& info() const { return info_; }
  uint32_t fourcc() const { return fourcc_; }
  std::size_t bufferCount() const { return buffers_.size(); }

 private:
  struct Mapped {
    void* data = nullptr;
    std::size_t length = 0;
  };
  Result<void> negotiate();
  Result<void> setFrameRate();
  Result<void> mapBuffers();
  Result<void> requeueHeld();
  // QUERYCTRL then S_CTRL; kNotSupported when the device has no such control.
  Result<void> setCtrl(uint32_t id, int64_t value, Control control);
  bool hasCtrl(uint32_t id);
  std::optional<int64_t> getCtrl(uint32_t id);
  Error errnoError(int negErrno, const std::string& what) const;

  V4l2Options options_;
  std::unique_ptr<V4l2Io> io_;
  int fd_ = -1;
  bool streaming_ = false;
  V4l2Info info_;
  uint32_t fourcc_ = 0, stride_ = 0;
  FrameFormat format_;
  std::vector<Mapped> buffers_;
  int held_ = -1;  // the buffer the current frame points into
  cv::Mat storage_;
  Frame frame_;
};

}  // namespace procam::camera
