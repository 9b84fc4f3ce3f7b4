#include "camera/libcamera/libcamera_camera.hpp"

#include <libcamera/libcamera.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

namespace procam::camera {
namespace {

namespace lc = libcamera;

// libcamera allows one CameraManager per process: share it between cameras.
Result<std::shared_ptr<lc::CameraManager>> manager() {
  static std::mutex mutex;
  static std::weak_ptr<lc::CameraManager> shared;
  std::lock_guard lock(mutex);
  if (auto m = shared.lock()) return m;
  auto m = std::shared_ptr<lc::CameraManager>(new lc::CameraManager(), [](lc::CameraManager* p) {
    p->stop();
    delete p;
  });
  if (int rc = m->start(); rc < 0)
    return fail(ErrorCode::kIo,
                std::string("libcamera: CameraManager does not start: ") + std::strerror(-rc));
  shared = m;
  return m;
}

// libcamera names packed RGB after DRM: RGB888 is B, G, R in memory.
std::optional<SourceFormat> sourceOf(const lc::PixelFormat& f) {
  if (f == lc::formats::R8) return SourceFormat::kGrey;
  if (f == lc::formats::YUYV) return SourceFormat::kYuyv;
  if (f == lc::formats::MJPEG) return SourceFormat::kMjpeg;
  if (f == lc::formats::RGB888) return SourceFormat::kBgr24;
  if (f == lc::formats::BGR888) return SourceFormat::kRgb24;
  return std::nullopt;
}

struct Mapping {
  void* data = MAP_FAILED;
  std::size_t length = 0;
};

}  // namespace

Result<std::vector<std::string>> libcameraCameraIds() {
  auto m = manager();
  if (!m) return tl::unexpected(m.error());
  std::vector<std::string> ids;
  for (const auto& c : (*m)->cameras()) ids.push_back(c->id());
  return ids;
}

struct LibcameraCamera::State {
  std::shared_ptr<lc::CameraManager> manager;
  std::shared_ptr<lc::Camera> camera;
  bool acquired = false, started = false;
  std::unique_ptr<lc::CameraConfiguration> config;
  std::unique_ptr<lc::FrameBufferAllocator> allocator;
  lc::Stream* stream = nullptr;
  std::vector<std::unique_ptr<lc::Request>> requests;
  std::map<const lc::FrameBuffer*, Mapping> mappings;
  SourceFormat source = SourceFormat::kGrey;
  FrameFormat format;
  uint32_t stride = 0;
  lc::ControlList pending;  // controls for the next queued requests
  int event_fd = -1;
  std::mutex mutex;
  std::deque<lc::Request*> completed;  // filled on libcamera's thread
  lc::Request* held = nullptr;
  std::optional<double> exposure_s, analogue_gain;  // the last frame's metadata
  cv::Mat storage;
  Frame frame;

  void onCompleted(lc::Request* r) {
    if (r->status() == lc::Request::RequestCancelled) return;
    {
      std::lock_guard lock(mutex);
      completed.push_back(r);
    }
    const uint64_t one = 1;
    (void)!::write(event_fd, &one, sizeof one);
  }

  int requeue(lc::Request* r) {
    r->reuse(lc::Request::ReuseBuffers);
    r->controls().merge(pending);
    return camera->queueRequest(r);
  }
};

LibcameraCamera::LibcameraCamera(LibcameraOptions options) : options_(std::move(options)) {}

LibcameraCamera::~LibcameraCamera() {
  stop();
}

FrameFormat LibcameraCamera::format() const {
  return s_ ? s_->format : FrameFormat{};
}

int LibcameraCamera::pollFd() const {
  return s_ ? s_->event_fd : -1;
}

Result<void> LibcameraCamera::start() {
  stop();
  auto m = manager();
  if (!m) return tl::unexpected(m.error());
  s_ = std::make_unique<State>();
  State& s = *s_;
  s.manager = *m;
  const auto cameras = s.manager->cameras();
  if (cameras.empty()) {
    stop();
    return fail(ErrorCode::kNoDevice, "libcamera: no camera (CameraManager lists none)");
  }
  s.camera = options_.id.empty() ? cameras.front() : s.manager->get(options_.id);
  if (!s.camera) {
    std::string list;
    for (const auto& c : cameras) list += (list.empty() ? "" : ", ") + c->id();
    stop();
    return fail(ErrorCode::kNoDevice,
                "libcamera: no camera '" + options_.id + "' (found: " + list + ")");
  }
  options_.id = s.camera->id();
  auto failed = [&](ErrorCode st, const std::string& what) {
    stop();
    return fail(st, name() + ": " + what);
  };
  if (s.camera->acquire() < 0) return failed(ErrorCode::kIo, "in use by another process");
  s.acquired = true;
  s.config = s.camera->generateConfiguration({lc::StreamRole::VideoRecording});
  if (!s.config || s.config->empty())
    return failed(ErrorCode::kNotSupported, "no stream configuration");
  lc::StreamConfiguration& sc = s.config->at(0);
  if (options_.width > 0) sc.size = {options_.width, options_.height};
  if (!options_.format.empty()) sc.pixelFormat = lc::PixelFormat::fromString(options_.format);
  sc.bufferCount = std::max(sc.bufferCount, options_.buffers);
  const std::string asked = sc.toString();
  if (s.config->validate() == lc::CameraConfiguration::Invalid)
    return failed(ErrorCode::kNotSupported, "configuration " + asked + " is invalid");
  if ((options_.width > 0 &&
       (sc.size.width != options_.width || sc.size.height != options_.height)) ||
      (!options_.format.empty() && sc.pixelFormat.toString() != options_.format))
    return failed(ErrorCode::kNotSupported,
                  "asked for " + asked + ", the camera offers " + sc.toString());
  const auto src = sourceOf(sc.pixelFormat);
  if (!src)
    return failed(ErrorCode::kNotSupported,
                  "format " + sc.pixelFormat.toString() + " cannot be converted");
  s.source = *src;
  if (s.camera->configure(s.config.get()) < 0) return failed(ErrorCode::kIo, "configure failed");
  s.stream = sc.stream();
  s.stride = sc.stride;
  s.format = {sc.size.width, sc.size.height, options_.pixel.value_or(naturalPixel(s.source))};
  if (s.format.pixel == PROCAM_PIXEL_GRAY16)
    return failed(ErrorCode::kNotSupported, "gray16 needs a 16-bit stream");

  s.allocator = std::make_unique<lc::FrameBufferAllocator>(s.camera);
  if (s.allocator->allocate(s.stream) < 0) return failed(ErrorCode::kIo, "cannot allocate buffers");
  for (const auto& buffer : s.allocator->buffers(s.stream)) {
    // Single-plane formats only: one mapping of plane 0.
    const auto& plane = buffer->planes()[0];
    Mapping map;
    map.length = plane.offset + plane.length;
    map.data = ::mmap(nullptr, map.length, PROT_READ, MAP_SHARED, plane.fd.get(), 0);
    if (map.data == MAP_FAILED)
      return failed(ErrorCode::kIo, std::string("mmap: ") + std::strerror(errno));
    s.mappings[buffer.get()] = map;
    auto request = s.camera->createRequest();
    if (!request || request->addBuffer(s.stream, buffer.get()) < 0)
      return failed(ErrorCode::kIo, "cannot create a request");
    s.requests.push_back(std::move(request));
  }
  s.event_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (s.event_fd < 0) return failed(ErrorCode::kIo, "eventfd failed");
  s.camera->requestCompleted.connect(&s, &State::onCompleted);
  if (s.camera->start() < 0) return failed(ErrorCode::kIo, "start failed");
  s.started = true;
  for (auto& r : s.requests)
    if (s.camera->queueRequest(r.get()) < 0)
      return failed(ErrorCode::kIo, "cannot queue a request");
  return {};
}

void LibcameraCamera::stop() {
  if (!s_) return;
  State& s = *s_;
  if (s.started) s.camera->stop();  // completes every queued request (cancelled)
  if (s.camera) s.camera->requestCompleted.disconnect(&s);
  s.requests.clear();
  for (auto& [buffer, map] : s.mappings)
    if (map.data != MAP_FAILED) ::munmap(map.data, map.length);
  s.mappings.clear();
  s.allocator.reset();
  if (s.acquired) s.camera->release();
  if (s.event_fd >= 0) ::close(s.event_fd);
  s_.reset();
}

Result<const Frame*> LibcameraCamera::capture(int timeout_ms) {
  if (!s_ || !s_->started) return fail(ErrorCode::kInvalidInput, name() + ": not streaming");
  State& s = *s_;
  if (s.held) {
    s.frame.image.release();
    lc::Request* r = std::exchange(s.held, nullptr);
    if (s.requeue(r) < 0)
      return fail(ErrorCode::kNoDevice, name() + ": cannot queue a request (camera gone?)");
  }
  uint64_t count = 0;
  (void)!::read(s.event_fd, &count, sizeof count);
  auto pop = [&]() -> lc::Request* {
    std::lock_guard lock(s.mutex);
    if (s.completed.empty()) return nullptr;
    lc::Request* r = s.completed.front();
    s.completed.pop_front();
    return r;
  };
  lc::Request* r = pop();
  if (!r && timeout_ms != 0) {
    pollfd p{s.event_fd, POLLIN, 0};
    ::poll(&p, 1, timeout_ms);
    (void)!::read(s.event_fd, &count, sizeof count);
    r = pop();
    if (!r)
      return fail(ErrorCode::kTimeout,
                  name() + ": no frame within " + std::to_string(timeout_ms) + " ms");
  }
  if (!r) return fail(ErrorCode::kAgain, name() + ": no frame waiting");
  {
    std::lock_guard lock(s.mutex);
    if (!s.completed.empty()) {
      const uint64_t one = 1;  // more are waiting: stay readable
      (void)!::write(s.event_fd, &one, sizeof one);
    }
  }
  s.held = r;
  const lc::FrameBuffer* buffer = r->findBuffer(s.stream);
  const auto& meta = buffer->metadata();
  if (meta.status != lc::FrameMetadata::FrameSuccess)
    return fail(ErrorCode::kIo, name() + ": frame " + std::to_string(meta.sequence) + " failed");
  const Mapping& map = s.mappings.at(buffer);
  const auto& plane = buffer->planes()[0];
  const SourceImage src{s.source,
                        static_cast<const uint8_t*>(map.data) + plane.offset,
                        meta.planes()[0].bytesused,
                        s.format.width,
                        s.format.height,
                        s.stride};
  if (auto ok = convertFrame(src, s.format.pixel, true, s.storage, s.frame); !ok)
    return fail(ok.error().code, name() + ": " + ok.error().message);
  const lc::ControlList& controls = r->metadata();
  if (auto us = controls.get(lc::controls::ExposureTime)) s.exposure_s = double(*us) * 1e-6;
  if (auto g = controls.get(lc::controls::AnalogueGain)) s.analogue_gain = double(*g);
  s.frame.sequence = meta.sequence;
  s.frame.timestamp_ns = meta.timestamp ? meta.timestamp : monotonicNs();
  return &s.frame;
}

std::optional<double> LibcameraCamera::exposureSeconds() {
  return s_ ? s_->exposure_s : std::nullopt;
}

std::optional<double> LibcameraCamera::gain() {
  return s_ ? s_->analogue_gain : std::nullopt;
}

Result<void> LibcameraCamera::setControl(Control control, double value) {
  if (!s_ || !s_->camera) return fail(ErrorCode::kInvalidInput, name() + ": not open");
  if (!std::isfinite(value))
    return fail(ErrorCode::kInvalidInput, name() + ": value must be finite");
  State& s = *s_;
  const lc::ControlInfoMap& info = s.camera->controls();
  auto has = [&](const lc::ControlId& id) { return info.find(&id) != info.end(); };
  switch (control) {
    case Control::kAutoExposure:
      if (!has(lc::controls::AeEnable)) {
        if (value == 0) return {};
        return unsupported(name(), control);
      }
      s.pending.set(lc::controls::AeEnable, value != 0);
      return {};
    case Control::kExposure:
      if (!has(lc::controls::ExposureTime)) return unsupported(name(), control);
      if (has(lc::controls::AeEnable)) s.pending.set(lc::controls::AeEnable, false);
      s.pending.set(lc::controls::ExposureTime, int32_t(std::lround(value * 1e6)));
      return {};
    case Control::kGain:
      if (!has(lc::controls::AnalogueGain)) return unsupported(name(), control);
      s.pending.set(lc::controls::AnalogueGain, float(value));
      return {};
    case Control::kWhiteBalance:
      if (!has(lc::controls::ColourTemperature)) return unsupported(name(), control);
      if (has(lc::controls::AwbEnable)) s.pending.set(lc::controls::AwbEnable, false);
      s.pending.set(lc::controls::ColourTemperature, int32_t(std::lround(value)));
      return {};
    case Control::kPowerLine:
      return unsupported(name(), control);
  }
  return unsupported(name(), control);
}

}  // namespace procam::camera
