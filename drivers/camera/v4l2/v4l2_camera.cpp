#include "camera/v4l2/v4l2_camera.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

namespace procam::camera {

std::optional<SourceFormat> sourceFormatOf(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_GREY:
      return SourceFormat::kGrey;
    case V4L2_PIX_FMT_Y16:
      return SourceFormat::kY16;
    case V4L2_PIX_FMT_YUYV:
      return SourceFormat::kYuyv;
    case V4L2_PIX_FMT_MJPEG:
    case V4L2_PIX_FMT_JPEG:
      return SourceFormat::kMjpeg;
    case V4L2_PIX_FMT_RGB24:
      return SourceFormat::kRgb24;
    case V4L2_PIX_FMT_BGR24:
      return SourceFormat::kBgr24;
    default:
      return std::nullopt;
  }
}

std::optional<uint32_t> parseFourcc(const std::string& text) {
  if (text.empty() || text.size() > 4) return std::nullopt;
  std::string t = text;
  t.resize(4, ' ');
  const uint32_t f = v4l2_fourcc(t[0], t[1], t[2], t[3]);
  if (!sourceFormatOf(f)) return std::nullopt;
  return f;
}

std::string fourccText(uint32_t f) {
  std::string s;
  for (int i = 0; i < 4; ++i) s += char((f >> (8 * i)) & 0xff);
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

namespace {

std::string cstr(const uint8_t* bytes, std::size_t n) {
  return std::string(reinterpret_cast<const char*>(bytes),
                     strnlen(reinterpret_cast<const char*>(bytes), n));
}

bool isCapture(const v4l2_capability& cap) {
  const uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  return (caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING);
}

V4l2Info infoOf(const std::string& devnode, const v4l2_capability& cap) {
  return {devnode, cstr(cap.driver, sizeof cap.driver), cstr(cap.card, sizeof cap.card),
          cstr(cap.bus_info, sizeof cap.bus_info)};
}

std::string sizeText(uint32_t w, uint32_t h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

}  // namespace

std::vector<V4l2Info> enumerateV4l2(V4l2Io& io, const std::string& dev_dir) {
  std::vector<std::string> nodes;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dev_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("video", 0) == 0) nodes.push_back(e.path().string());
  }
  std::sort(nodes.begin(), nodes.end());
  std::vector<V4l2Info> out;
  for (const auto& node : nodes) {
    const int fd = io.open(node);
    if (fd < 0) continue;
    v4l2_capability cap{};
    if (io.ioctl(fd, VIDIOC_QUERYCAP, &cap) == 0 && isCapture(cap))
      out.push_back(infoOf(node, cap));
    io.close(fd);
  }
  return out;
}

V4l2Camera::V4l2Camera(V4l2Options options, std::unique_ptr<V4l2Io> io)
    : options_(std::move(options)), io_(std::move(io)) {}

V4l2Camera::~V4l2Camera() {
  stop();
}

Error V4l2Camera::errnoError(int negErrno, const std::string& what) const {
  const int e = -negErrno;
  const std::string text = name() + ": " + what + ": " + std::strerror(e);
  // The node is gone (unplugged) or never was: the daemon reopens it when it returns.
  if (e == ENODEV || e == ENXIO || e == ENOENT) return {ErrorCode::kNoDevice, text};
  if (e == EINVAL || e == ERANGE) return {ErrorCode::kInvalidInput, text};
  if (e == ETIMEDOUT) return {ErrorCode::kTimeout, text};
  return {ErrorCode::kIo, text};
}

Result<void> V4l2Camera::start() {
  stop();
  if (options_.buffers < 4)
    return fail(ErrorCode::kInvalidInput, name() + ": at least 4 buffers are needed");
  const int fd = io_->open(options_.device);
  if (fd < 0) return tl::unexpected(errnoError(fd, "open"));
  fd_ = fd;
  v4l2_capability cap{};
  if (int rc = io_->ioctl(fd_, VIDIOC_QUERYCAP, &cap); rc < 0) {
    auto e = errnoError(rc, "VIDIOC_QUERYCAP");
    stop();
    return tl::unexpected(e);
  }
  info_ = infoOf(options_.device, cap);
  auto ok =
      isCapture(cap)
          ? Result<void>()
          : fail(ErrorCode::kNotSupported,
                 name() + " (" + info_.card + "): not a video capture device with streaming I/O");
  if (ok) ok = negotiate();
  if (ok) ok = setFrameRate();
  if (ok) ok = mapBuffers();
  if (ok) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (int rc = io_->ioctl(fd_, VIDIOC_STREAMON, &type); rc < 0)
      ok = tl::unexpected(errnoError(rc, "VIDIOC_STREAMON"));
    else
      streaming_ = true;
  }
  if (!ok) stop();
  return ok;
}

Result<void> V4l2Camera::negotiate() {
  std::vector<uint32_t> offered;
  for (uint32_t i = 0;; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    const int rc = io_->ioctl(fd_, VIDIOC_ENUM_FMT, &d);
    if (rc == -EINVAL) break;  // past the last format
    if (rc < 0) return tl::unexpected(errnoError(rc, "VIDIOC_ENUM_FMT"));
    offered.push_back(d.pixelformat);
  }
  auto has = [&](uint32_t f) {
    return std::find(offered.begin(), offered.end(), f) != offered.end();
  };
  std::string list;
  for (uint32_t f : offered) list += (list.empty() ? "" : ", ") + fourccText(f);
  if (options_.fourcc) {
    if (!has(*options_.fourcc))
      return fail(ErrorCode::kNotSupported, name() + ": format " + fourccText(*options_.fourcc) +
                                                " not offered (offers: " + list + ")");
    fourcc_ = *options_.fourcc;
  } else {
    fourcc_ = 0;
    for (uint32_t f : kV4l2Preference)
      if (!fourcc_ && has(f)) fourcc_ = f;
    if (!fourcc_)
      return fail(
          ErrorCode::kNotSupported,
          name() + ": none of the device's formats can be converted (offers: " + list + ")");
  }

  // Frame sizes of that format: discrete ones, or a stepwise/continuous range.
  std::vector<std::pair<uint32_t, uint32_t>> sizes;
  std::optional<v4l2_frmsize_stepwise> range;
  for (uint32_t i = 0;; ++i) {
    v4l2_frmsizeenum s{};
    s.index = i;
    s.pixel_format = fourcc_;
    const int rc = io_->ioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &s);
    if (rc < 0) break;  // past the last, or the driver does not enumerate sizes
    if (s.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      sizes.emplace_back(s.discrete.width, s.discrete.height);
    } else {
      range = s.stepwise;
      break;
    }
  }
  uint32_t w = options_.width, h = options_.height;
  const bool asked = w > 0 && h > 0;
  if (!sizes.empty()) {
    std::string offers;
    for (auto [sw, sh] : sizes) offers += (offers.empty() ? "" : ", ") + sizeText(sw, sh);
    if (asked) {
      if (std::find(sizes.begin(), sizes.end(), std::make_pair(w, h)) == sizes.end())
        return fail(ErrorCode::kNotSupported, name() + ": " + sizeText(w, h) + " " +
                                                  fourccText(fourcc_) +
                                                  " not offered (offers: " + offers + ")");
    } else {
      auto largest = *std::max_element(sizes.begin(), sizes.end(), [](auto a, auto b) {
        return uint64_t(a.first) * a.second < uint64_t(b.first) * b.second;
      });
      w = largest.first;
      h = largest.second;
    }
  } else if (range) {
    if (asked && (w < range->min_width || w > range->max_width || h < range->min_height ||
                  h > range->max_height))
      return fail(ErrorCode::kNotSupported,
                  name() + ": " + sizeText(w, h) + " outside the device's range " +
                      sizeText(range->min_width, range->min_height) + " .. " +
                      sizeText(range->max_width, range->max_height));
    if (!asked) {
      w = range->max_width;
      h = range->max_height;
    }
  }

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (w == 0 || h == 0) {  // no sizes enumerated and none asked: keep the current one
    if (int rc = io_->ioctl(fd_, VIDIOC_G_FMT, &fmt); rc < 0)
      return tl::unexpected(errnoError(rc, "VIDIOC_G_FMT"));
    w = fmt.fmt.pix.width;
    h = fmt.fmt.pix.height;
  }
  fmt = {};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = w;
  fmt.fmt.pix.height = h;
  fmt.fmt.pix.pixelformat = fourcc_;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  if (int rc = io_->ioctl(fd_, VIDIOC_S_FMT, &fmt); rc < 0)
    return tl::unexpected(
        errnoError(rc, "VIDIOC_S_FMT " + sizeText(w, h) + " " + fourccText(fourcc_)));
  // S_FMT may adjust what it was given; G_FMT says what the device really streams.
  if (int rc = io_->ioctl(fd_, VIDIOC_G_FMT, &fmt); rc < 0)
    return tl::unexpected(errnoError(rc, "VIDIOC_G_FMT"));
  if (fmt.fmt.pix.pixelformat != fourcc_)
    return fail(ErrorCode::kNotSupported, name() + ": asked for " + fourccText(fourcc_) +
                                              ", the device chose " +
                                              fourccText(fmt.fmt.pix.pixelformat));
  if (asked && (fmt.fmt.pix.width != w || fmt.fmt.pix.height != h))
    return fail(ErrorCode::kNotSupported, name() + ": asked for " + sizeText(w, h) +
                                              ", the device chose " +
                                              sizeText(fmt.fmt.pix.width, fmt.fmt.pix.height));
  const SourceFormat src = *sourceFormatOf(fourcc_);
  const uint32_t bpp = src == SourceFormat::kGrey                                  ? 1
                       : src == SourceFormat::kMjpeg                               ? 0
                       : (src == SourceFormat::kY16 || src == SourceFormat::kYuyv) ? 2
                                                                                   : 3;
  stride_ = fmt.fmt.pix.bytesperline ? fmt.fmt.pix.bytesperline : fmt.fmt.pix.width * bpp;
  const procam_pixel_format pixel = options_.pixel.value_or(naturalPixel(src));
  if (pixel == PROCAM_PIXEL_GRAY16 && src != SourceFormat::kY16)
    return fail(ErrorCode::kNotSupported,
                name() + ": " + fourccText(fourcc_) + " is 8-bit; gray16 needs Y16");
  format_ = {fmt.fmt.pix.width, fmt.fmt.pix.height, pixel};
  return {};
}

Result<void> V4l2Camera::setFrameRate() {
  if (!(options_.fps > 0)) return {};
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (int rc = io_->ioctl(fd_, VIDIOC_G_PARM, &parm); rc < 0 && rc != -ENOTTY && rc != -EINVAL)
    return tl::unexpected(errnoError(rc, "VIDIOC_G_PARM"));
  if (!(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME))
    return fail(ErrorCode::kNotSupported, name() + ": frame rate is not supported by this device");
  parm.parm.capture.timeperframe = {1000, uint32_t(std::lround(options_.fps * 1000))};
  if (int rc = io_->ioctl(fd_, VIDIOC_S_PARM, &parm); rc < 0)
    return tl::unexpected(errnoError(rc, "VIDIOC_S_PARM"));
  return {};
}

Result<void> V4l2Camera::mapBuffers() {
  v4l2_requestbuffers req{};
  req.count = options_.buffers;
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (int rc = io_->ioctl(fd_, VIDIOC_REQBUFS, &req); rc < 0)
    return tl::unexpected(errnoError(rc, "VIDIOC_REQBUFS (mmap)"));
  // The driver may grant fewer: with fewer than 4 one held frame stalls the stream.
  if (req.count < 4)
    return fail(ErrorCode::kIo, name() + ": the device granted " + std::to_string(req.count) +
                                    " buffers, at least 4 are needed");
  buffers_.resize(req.count);
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.index = i;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (int rc = io_->ioctl(fd_, VIDIOC_QUERYBUF, &b); rc < 0)
      return tl::unexpected(errnoError(rc, "VIDIOC_QUERYBUF"));
    int error = 0;
    void* p = io_->mmap(fd_, b.length, b.m.offset, &error);
    if (!p) return tl::unexpected(errnoError(-error, "mmap of buffer " + std::to_string(i)));
    buffers_[i] = {p, b.length};
    if (int rc = io_->ioctl(fd_, VIDIOC_QBUF, &b); rc < 0)
      return tl::unexpected(errnoError(rc, "VIDIOC_QBUF"));
  }
  return {};
}

void V4l2Camera::stop() {
  if (fd_ < 0) return;
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    io_->ioctl(fd_, VIDIOC_STREAMOFF, &type);  // a vanished device fails here; nothing to do
    streaming_ = false;
  }
  for (auto& m : buffers_)
    if (m.data) io_->munmap(m.data, m.length);
  if (!buffers_.empty()) {
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    io_->ioctl(fd_, VIDIOC_REQBUFS, &req);  // count 0 frees the driver's buffers
  }
  buffers_.clear();
  held_ = -1;
  frame_.image.release();
  io_->close(fd_);
  fd_ = -1;
}

Result<void> V4l2Camera::requeueHeld() {
  if (held_ < 0) return {};
  v4l2_buffer b{};
  b.index = uint32_t(held_);
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  frame_.image.release();  // the frame no longer points into the buffer
  held_ = -1;
  if (int rc = io_->ioctl(fd_, VIDIOC_QBUF, &b); rc < 0)
    return tl::unexpected(errnoError(rc, "VIDIOC_QBUF"));
  return {};
}

Result<const Frame*> V4l2Camera::capture(int timeout_ms) {
  if (!streaming_) return fail(ErrorCode::kInvalidInput, name() + ": not streaming");
  if (auto ok = requeueHeld(); !ok) return tl::unexpected(ok.error());
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  int rc = io_->ioctl(fd_, VIDIOC_DQBUF, &b);
  if (rc == -EAGAIN) {
    if (timeout_ms == 0) return fail(ErrorCode::kAgain, name() + ": no frame waiting");
    bool hangup = false;
    const int p = io_->poll(fd_, timeout_ms, &hangup);
    if (p < 0) return tl::unexpected(errnoError(p, "poll"));
    if (p == 0)
      return fail(ErrorCode::kTimeout,
                  name() + ": no frame within " + std::to_string(timeout_ms) + " ms");
    rc = io_->ioctl(fd_, VIDIOC_DQBUF, &b);
    if (rc == -EAGAIN)
      return hangup ? fail(ErrorCode::kNoDevice, name() + ": the device hung up")
                    : fail(ErrorCode::kAgain, name() + ": no frame waiting");
  }
  if (rc < 0) return tl::unexpected(errnoError(rc, "VIDIOC_DQBUF"));
  if (b.index >= buffers_.size())
    return fail(ErrorCode::kIo,
                name() + ": the device returned unknown buffer " + std::to_string(b.index));
  held_ = int(b.index);
  if (b.flags & V4L2_BUF_FLAG_ERROR) {
    (void)requeueHeld();
    return fail(ErrorCode::kIo, name() + ": the device flagged frame " +
                                    std::to_string(b.sequence) + " as corrupt");
  }
  const Mapped& m = buffers_[b.index];
  const std::size_t used = b.bytesused ? std::min<std::size_t>(b.bytesused, m.length) : m.length;
  const SourceImage src{*sourceFormatOf(fourcc_),
                        static_cast<const uint8_t*>(m.data),
                        used,
                        format_.width,
                        format_.height,
                        stride_};
  // The buffer stays dequeued until the next capture, so the frame may point into it.
  if (auto ok = convertFrame(src, format_.pixel, true, storage_, frame_); !ok) {
    (void)requeueHeld();
    return fail(ok.error().code, name() + ": " + ok.error().message);
  }
  frame_.sequence = b.sequence;
  const bool monotonic =
      (b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  frame_.timestamp_ns = monotonic ? uint64_t(b.timestamp.tv_sec) * 1'000'000'000ull +
                                        uint64_t(b.timestamp.tv_usec) * 1000ull
                                  : monotonicNs();
  return &frame_;
}

bool V4l2Camera::hasCtrl(uint32_t id) {
  v4l2_queryctrl q{};
  q.id = id;
  return io_->ioctl(fd_, VIDIOC_QUERYCTRL, &q) == 0 && !(q.flags & V4L2_CTRL_FLAG_DISABLED);
}

std::optional<int64_t> V4l2Camera::getCtrl(uint32_t id) {
  if (fd_ < 0 || !hasCtrl(id)) return std::nullopt;
  v4l2_control c{};
  c.id = id;
  if (io_->ioctl(fd_, VIDIOC_G_CTRL, &c) != 0) return std::nullopt;
  return c.value;
}

std::optional<double> V4l2Camera::exposureSeconds() {
  auto v = getCtrl(V4L2_CID_EXPOSURE_ABSOLUTE);
  if (!v) return std::nullopt;
  return double(*v) * 1e-4;
}

std::optional<double> V4l2Camera::gain() {
  auto v = getCtrl(V4L2_CID_GAIN);
  if (!v) return std::nullopt;
  return double(*v);
}

Result<void> V4l2Camera::setCtrl(uint32_t id, int64_t value, Control control) {
  if (fd_ < 0) return fail(ErrorCode::kInvalidInput, name() + ": not open");
  v4l2_queryctrl q{};
  q.id = id;
  if (int rc = io_->ioctl(fd_, VIDIOC_QUERYCTRL, &q); rc < 0) {
    if (rc == -EINVAL) return unsupported(name(), control);
    return tl::unexpected(errnoError(rc, "VIDIOC_QUERYCTRL"));
  }
  if (q.flags & (V4L2_CTRL_FLAG_DISABLED | V4L2_CTRL_FLAG_READ_ONLY))
    return unsupported(name(), control);
  if (value < q.minimum || value > q.maximum)
    return fail(ErrorCode::kInvalidInput,
                name() + ": " + toString(control) + " value " + std::to_string(value) +
                    " outside the device's range [" + std::to_string(q.minimum) + ", " +
                    std::to_string(q.maximum) + "]");
  v4l2_control c{id, int32_t(value)};
  if (int rc = io_->ioctl(fd_, VIDIOC_S_CTRL, &c); rc < 0)
    return tl::unexpected(errnoError(rc, std::string("setting ") + toString(control)));
  return {};
}

Result<void> V4l2Camera::setControl(Control control, double value) {
  if (!std::isfinite(value))
    return fail(ErrorCode::kInvalidInput, name() + ": " + toString(control) + " must be finite");
  switch (control) {
    case Control::kExposure:
      // V4L2_CID_EXPOSURE_ABSOLUTE counts 100 µs units.
      return setCtrl(V4L2_CID_EXPOSURE_ABSOLUTE, std::llround(value * 1e4), control);
    case Control::kAutoExposure: {
      // A camera without automatic exposure is already manual.
      if (value == 0 && !hasCtrl(V4L2_CID_EXPOSURE_AUTO)) return {};
      if (value == 0) return setCtrl(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, control);
      // UVC cameras often offer only aperture priority as their automatic mode.
      auto ok = setCtrl(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_AUTO, control);
      if (!ok && ok.error().code == ErrorCode::kInvalidInput)
        ok = setCtrl(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_APERTURE_PRIORITY, control);
      return ok;
    }
    case Control::kGain:
      if (hasCtrl(V4L2_CID_AUTOGAIN)) {
        if (auto ok = setCtrl(V4L2_CID_AUTOGAIN, 0, control); !ok) return ok;
      }
      return setCtrl(V4L2_CID_GAIN, std::llround(value), control);
    case Control::kWhiteBalance:
      if (hasCtrl(V4L2_CID_AUTO_WHITE_BALANCE)) {
        if (auto ok = setCtrl(V4L2_CID_AUTO_WHITE_BALANCE, 0, control); !ok) return ok;
      }
      return setCtrl(V4L2_CID_WHITE_BALANCE_TEMPERATURE, std::llround(value), control);
    case Control::kPowerLine: {
      const int64_t menu = value == 0    ? V4L2_CID_POWER_LINE_FREQUENCY_DISABLED
                           : value == 50 ? V4L2_CID_POWER_LINE_FREQUENCY_50HZ
                           : value == 60 ? V4L2_CID_POWER_LINE_FREQUENCY_60HZ
                                         : -1;
      if (menu < 0)
        return fail(ErrorCode::kInvalidInput,
                    name() + ": power-line frequency must be 0, 50 or 60 Hz");
      return setCtrl(V4L2_CID_POWER_LINE_FREQUENCY, menu, control);
    }
  }
  return unsupported(name(), control);
}

}  // namespace procam::camera
