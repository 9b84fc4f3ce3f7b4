#include "camera/aravis/aravis_camera.hpp"

#include <arv.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

namespace procam::camera {
namespace {

// The message of a GError, which is freed.
std::string take(GError*& error) {
  std::string m = error && error->message ? error->message : "unknown error";
  g_clear_error(&error);
  return m;
}

std::optional<SourceFormat> sourceOf(ArvPixelFormat f) {
  switch (f) {
    case ARV_PIXEL_FORMAT_MONO_8:
      return SourceFormat::kGrey;
    case ARV_PIXEL_FORMAT_MONO_16:
      return SourceFormat::kY16;
    case ARV_PIXEL_FORMAT_RGB_8_PACKED:
      return SourceFormat::kRgb24;
    case ARV_PIXEL_FORMAT_BGR_8_PACKED:
      return SourceFormat::kBgr24;
    case ARV_PIXEL_FORMAT_YUV_422_YUYV_PACKED:
      return SourceFormat::kYuyv;
    default:
      return std::nullopt;
  }
}

// Releases of gone cameras run off the caller's thread (each waits out Aravis' register
// timeouts, about 10 s). The threads are joined when this object is destroyed: at exit
// for procamd, or when a module holding the driver is unloaded, so no release outlives
// the code it runs.
class DeadCameraReleaser {
 public:
  ~DeadCameraReleaser() {
    std::vector<std::thread> threads;
    {
      std::lock_guard lock(mutex_);
      threads.swap(threads_);
    }
    for (auto& t : threads) t.join();
  }
  void release(ArvStream* stream, ArvCamera* camera) {
    std::lock_guard lock(mutex_);
    // Finished releases are joined here so the list stays short.
    std::erase_if(threads_, [this](std::thread& t) {
      if (!done_.contains(t.get_id())) return false;
      done_.erase(t.get_id());
      t.join();
      return true;
    });
    threads_.emplace_back([this, stream, camera] {
      if (stream) g_object_unref(stream);
      g_object_unref(camera);
      std::lock_guard done_lock(mutex_);
      done_.insert(std::this_thread::get_id());
    });
  }

 private:
  std::mutex mutex_;
  std::vector<std::thread> threads_;
  std::set<std::thread::id> done_;
};

DeadCameraReleaser& deadCameraReleaser() {
  static DeadCameraReleaser releaser;
  return releaser;
}

uint32_t bytesPerPixel(SourceFormat f) {
  return f == SourceFormat::kGrey                                ? 1
         : (f == SourceFormat::kY16 || f == SourceFormat::kYuyv) ? 2
                                                                 : 3;
}

// Aravis stamps buffers with the host's real-time clock on arrival; the pipeline's
// timestamps are CLOCK_MONOTONIC, so shift by the clocks' current offset.
uint64_t toMonotonic(uint64_t realtime_ns) {
  timespec rt{};
  clock_gettime(CLOCK_REALTIME, &rt);
  const uint64_t now_rt = uint64_t(rt.tv_sec) * 1'000'000'000ull + uint64_t(rt.tv_nsec);
  const uint64_t now_mono = monotonicNs();
  const uint64_t age = now_rt > realtime_ns ? now_rt - realtime_ns : 0;
  return age < now_mono ? now_mono - age : now_mono;
}

}  // namespace

EventFd::EventFd() : fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

EventFd::~EventFd() {
  if (fd_ >= 0) ::close(fd_);
}

void EventFd::signal() const {
  const uint64_t one = 1;
  // Can fail only with EAGAIN (the counter is full): readable already.
  if (fd_ >= 0) (void)!::write(fd_, &one, sizeof one);
}

void EventFd::drain() const {
  uint64_t n = 0;
  while (fd_ >= 0 && ::read(fd_, &n, sizeof n) > 0) {
  }
}

AravisCamera::AravisCamera(AravisOptions options) : options_(std::move(options)) {}

void AravisCamera::onControlLost(void*, void* self) {
  auto* cam = static_cast<AravisCamera*>(self);  // from Aravis' heartbeat thread
  {
    std::lock_guard lock(cam->watchdog_mutex_);
    if (cam->gone_reason_.empty()) cam->gone_reason_ = "control lost (the camera is gone)";
  }
  cam->markGone();
}

void AravisCamera::markGone() const {
  lost_ = true;
  gone_fd_.signal();
}

void AravisCamera::startWatchdog() {
  {
    std::lock_guard lock(watchdog_mutex_);
    watchdog_stop_ = false;
  }
  if (options_.probe_ms > 0) watchdog_ = std::thread([this] { watch(); });
}

void AravisCamera::stopWatchdog() {
  {
    std::lock_guard lock(watchdog_mutex_);
    watchdog_stop_ = true;
  }
  watchdog_wake_.notify_all();
  // At most one register read (Aravis' retries, ~2.5 s on a gone camera) to wait for.
  if (watchdog_.joinable()) watchdog_.join();
}

void AravisCamera::watch() {
  ArvDevice* device = arv_camera_get_device(camera_);
  std::unique_lock lock(watchdog_mutex_);
  for (;;) {
    const auto period = std::chrono::milliseconds(options_.probe_ms);
    if (watchdog_wake_.wait_for(lock, period, [this] { return watchdog_stop_; })) return;
    if (lost_) return;
    lock.unlock();
    // Address 0 is a bootstrap register of both GigE Vision (Version) and
    // USB3 Vision (the ABRM's GenCP version); the device serialises register
    // access, so this runs beside captures and controls on other threads.
    guint32 value = 0;
    GError* error = nullptr;
    const bool answered = arv_device_read_register(device, 0, &value, &error);
    const std::string reason = answered ? std::string() : take(error);
    lock.lock();
    if (!answered && !watchdog_stop_) {
      if (gone_reason_.empty()) gone_reason_ = "the camera no longer answers: " + reason;
      lock.unlock();
      markGone();
      return;
    }
  }
}

AravisCamera::~AravisCamera() {
  stop();
}

Result<void> AravisCamera::start() {
  stop();
  if (options_.buffers < 2)
    return fail(ErrorCode::kInvalidInput, name() + ": at least 2 stream buffers are needed");
  GError* error = nullptr;
  camera_ = arv_camera_new(options_.id.empty() ? nullptr : options_.id.c_str(), &error);
  if (!camera_) return fail(ErrorCode::kNoDevice, name() + ": cannot open: " + take(error));
  lost_ = false;
  gone_fd_.drain();
  {
    std::lock_guard lock(watchdog_mutex_);
    gone_reason_.clear();
  }
  control_lost_handler_ = g_signal_connect(arv_camera_get_device(camera_), "control-lost",
                                           G_CALLBACK(onControlLost), this);
  auto ok = configure();
  if (!ok) {
    stop();
    return ok;
  }
  startWatchdog();
  return ok;
}

Result<void> AravisCamera::configure() {
  GError* error = nullptr;
  auto failed = [&](ErrorCode s, const std::string& what) {
    return fail(s, name() + ": " + what + ": " + take(error));
  };
  // Acquisition may still run from a previous client that vanished.
  arv_camera_stop_acquisition(camera_, &error);
  g_clear_error(&error);
  if (options_.width > 0 && options_.height > 0) {
    arv_camera_set_region(camera_, 0, 0, int(options_.width), int(options_.height), &error);
    if (error) return failed(ErrorCode::kNotSupported, "region");
  }
  if (!options_.pixel_format.empty()) {
    arv_camera_set_pixel_format_from_string(camera_, options_.pixel_format.c_str(), &error);
    if (error) return failed(ErrorCode::kNotSupported, "pixel format " + options_.pixel_format);
  }
  if (arv_camera_is_gv_device(camera_)) {
    if (options_.packet_size > 0)
      arv_camera_gv_set_packet_size(camera_, options_.packet_size, &error);
    else
      arv_camera_gv_auto_packet_size(camera_, &error);
    if (error) return failed(ErrorCode::kIo, "packet size");
  }
  if (options_.fps > 0) {
    arv_camera_set_frame_rate(camera_, options_.fps, &error);
    if (error) return failed(ErrorCode::kNotSupported, "frame rate");
  }
  int x = 0, y = 0, w = 0, h = 0;
  arv_camera_get_region(camera_, &x, &y, &w, &h, &error);
  if (error) return failed(ErrorCode::kIo, "reading the region");
  if (options_.width > 0 && (uint32_t(w) != options_.width || uint32_t(h) != options_.height))
    return fail(ErrorCode::kNotSupported, name() + ": asked for " + std::to_string(options_.width) +
                                              "x" + std::to_string(options_.height) +
                                              ", the camera set " + std::to_string(w) + "x" +
                                              std::to_string(h));
  const ArvPixelFormat pf = arv_camera_get_pixel_format(camera_, &error);
  if (error) return failed(ErrorCode::kIo, "reading the pixel format");
  const auto src = sourceOf(pf);
  if (!src)
    return fail(ErrorCode::kNotSupported,
                name() + ": pixel format 0x" + std::to_string(pf) +
                    " cannot be converted (use Mono8, Mono16, RGB8Packed, BGR8Packed, YUV422)");
  source_ = *src;
  const procam_pixel_format pixel = options_.pixel.value_or(naturalPixel(source_));
  if (pixel == PROCAM_PIXEL_GRAY16 && source_ != SourceFormat::kY16)
    return fail(ErrorCode::kNotSupported, name() + ": gray16 needs a Mono16 stream");
  format_ = {uint32_t(w), uint32_t(h), pixel};

  stream_ = arv_camera_create_stream(camera_, nullptr, nullptr, &error);
  if (!stream_) return failed(ErrorCode::kIo, "creating the stream");
  const guint payload = arv_camera_get_payload(camera_, &error);
  if (error) return failed(ErrorCode::kIo, "reading the payload size");
  for (unsigned i = 0; i < options_.buffers; ++i)
    arv_stream_push_buffer(stream_, arv_buffer_new_allocate(payload));
  arv_camera_set_acquisition_mode(camera_, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  if (error) return failed(ErrorCode::kIo, "acquisition mode");
  arv_camera_start_acquisition(camera_, &error);
  if (error) return failed(ErrorCode::kIo, "starting acquisition");
  failed_ = 0;
  return {};
}

void AravisCamera::releaseHeld() {
  if (!held_) return;
  frame_.image.release();
  if (stream_)
    arv_stream_push_buffer(stream_, held_);
  else
    g_object_unref(held_);
  held_ = nullptr;
}

void AravisCamera::stop() {
  stopWatchdog();
  if (camera_ && control_lost_handler_ != 0) {
    // The camera may outlive this object (released on a thread of its own below).
    g_signal_handler_disconnect(arv_camera_get_device(camera_), control_lost_handler_);
  }
  control_lost_handler_ = 0;
  releaseHeld();
  if (camera_ && stream_ && !lost_) {
    GError* error = nullptr;
    arv_camera_stop_acquisition(camera_, &error);
    g_clear_error(&error);
  }
  if (lost_ && camera_) {
    // Releasing a gone GigE camera waits out Aravis' register timeouts (about 10 s here);
    // the daemon closes lost devices on its loop thread, so let that happen elsewhere.
    deadCameraReleaser().release(stream_, camera_);
    stream_ = nullptr;
    camera_ = nullptr;
  }
  g_clear_object(&stream_);
  g_clear_object(&camera_);
}

Result<void> AravisCamera::checkAlive() const {
  if (lost_) {
    std::lock_guard lock(watchdog_mutex_);
    return fail(ErrorCode::kNoDevice,
                name() + ": " +
                    (gone_reason_.empty() ? "control lost (the camera is gone)" : gone_reason_));
  }
  GError* error = nullptr;
  arv_camera_get_payload(camera_, &error);
  if (error) {
    const std::string reason = "the camera no longer answers: " + take(error);
    {
      std::lock_guard lock(watchdog_mutex_);
      if (gone_reason_.empty()) gone_reason_ = reason;
    }
    markGone();  // stop() then skips the commands a gone camera would time out on
    return fail(ErrorCode::kNoDevice, name() + ": " + reason);
  }
  return {};
}

Result<const Frame*> AravisCamera::capture(int timeout_ms) {
  if (!stream_) return fail(ErrorCode::kInvalidInput, name() + ": not streaming");
  releaseHeld();
  if (lost_) return tl::unexpected(checkAlive().error());
  // A frame that lost packets on the network (GigE Vision over UDP) is dropped and
  // counted, and the wait goes on for the next one within the same time.
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(timeout_ms < 0 ? 3'600'000 : timeout_ms);
  ArvBuffer* b = nullptr;
  int incomplete = -1;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
        deadline - std::chrono::steady_clock::now());
    b = timeout_ms == 0
            ? arv_stream_try_pop_buffer(stream_)
            : (left.count() > 0 ? arv_stream_timeout_pop_buffer(stream_, guint64(left.count()))
                                : nullptr);
    if (!b || arv_buffer_get_status(b) == ARV_BUFFER_STATUS_SUCCESS) break;
    ++failed_;
    incomplete = int(arv_buffer_get_status(b));
    held_ = b;
    releaseHeld();
    b = nullptr;
    if (timeout_ms == 0) break;
  }
  if (!b && incomplete >= 0) {
    return fail(
        timeout_ms == 0 ? ErrorCode::kAgain : ErrorCode::kIo,
        name() + ": frame incomplete (Aravis buffer status " + std::to_string(incomplete) + ")");
  }
  if (!b) {
    if (timeout_ms == 0) {
      if (lost_) return tl::unexpected(checkAlive().error());
      return fail(ErrorCode::kAgain, name() + ": no frame waiting");
    }
    // Silence: either a slow camera or a gone one; ask it something.
    if (auto alive = checkAlive(); !alive) return tl::unexpected(alive.error());
    return fail(ErrorCode::kTimeout,
                name() + ": no frame within " + std::to_string(timeout_ms) + " ms");
  }
  held_ = b;
  std::size_t size = 0;
  const auto* data = static_cast<const uint8_t*>(arv_buffer_get_image_data(b, &size));
  const uint32_t w = uint32_t(arv_buffer_get_image_width(b));
  const uint32_t h = uint32_t(arv_buffer_get_image_height(b));
  const SourceImage src{source_, data, size, w, h, w * bytesPerPixel(source_)};
  if (auto ok = convertFrame(src, format_.pixel, true, storage_, frame_); !ok) {
    releaseHeld();
    return fail(ok.error().code, name() + ": " + ok.error().message);
  }
  frame_.sequence = arv_buffer_get_frame_id(b);
  const uint64_t sys = arv_buffer_get_system_timestamp(b);
  frame_.timestamp_ns = sys ? toMonotonic(sys) : monotonicNs();
  return &frame_;
}

Result<double> AravisCamera::exposure() const {
  if (!camera_) return fail(ErrorCode::kInvalidInput, name() + ": not open");
  GError* error = nullptr;
  const double us = arv_camera_get_exposure_time(camera_, &error);
  if (error) return fail(ErrorCode::kIo, name() + ": reading exposure: " + take(error));
  return us * 1e-6;
}

std::optional<double> AravisCamera::exposureSeconds() {
  auto e = exposure();
  if (!e || !std::isfinite(*e)) return std::nullopt;
  return *e;
}

std::optional<double> AravisCamera::gain() {
  if (!camera_) return std::nullopt;
  GError* error = nullptr;
  const bool available = arv_camera_is_gain_available(camera_, &error);
  g_clear_error(&error);
  if (!available) return std::nullopt;
  const double db = arv_camera_get_gain(camera_, &error);
  if (error) {
    g_clear_error(&error);
    return std::nullopt;
  }
  return std::isfinite(db) ? std::optional<double>(db) : std::nullopt;
}

Result<void> AravisCamera::setControl(Control control, double value) {
  if (!camera_) return fail(ErrorCode::kInvalidInput, name() + ": not open");
  if (!std::isfinite(value))
    return fail(ErrorCode::kInvalidInput, name() + ": " + toString(control) + " must be finite");
  GError* error = nullptr;
  auto io = [&](const char* what) {
    return fail(ErrorCode::kIo, name() + ": " + what + ": " + take(error));
  };
  auto inRange = [&](double v, double lo, double hi, const char* unit) -> Result<void> {
    if (v >= lo && v <= hi) return {};
    return fail(ErrorCode::kInvalidInput, name() + ": " + toString(control) + " " +
                                              std::to_string(v) + " " + unit +
                                              " outside the camera's range [" + std::to_string(lo) +
                                              ", " + std::to_string(hi) + "]");
  };
  switch (control) {
    case Control::kAutoExposure: {
      const bool available = arv_camera_is_exposure_auto_available(camera_, &error);
      g_clear_error(&error);
      if (!available) {
        if (value == 0) return {};  // no automatic exposure: already manual
        return unsupported(name(), control);
      }
      arv_camera_set_exposure_time_auto(camera_, value == 0 ? ARV_AUTO_OFF : ARV_AUTO_CONTINUOUS,
                                        &error);
      if (error) return io("ExposureAuto");
      return {};
    }
    case Control::kExposure: {
      const bool available = arv_camera_is_exposure_time_available(camera_, &error);
      g_clear_error(&error);
      if (!available) return unsupported(name(), control);
      double lo = 0, hi = 0;
      arv_camera_get_exposure_time_bounds(camera_, &lo, &hi, &error);
      if (error) return io("exposure bounds");
      const double us = value * 1e6;
      if (auto ok = inRange(us, lo, hi, "us"); !ok) return ok;
      arv_camera_set_exposure_time(camera_, us, &error);
      if (error) return io("ExposureTime");
      return {};
    }
    case Control::kGain: {
      const bool available = arv_camera_is_gain_available(camera_, &error);
      g_clear_error(&error);
      if (!available) return unsupported(name(), control);
      if (arv_camera_is_gain_auto_available(camera_, &error)) {
        arv_camera_set_gain_auto(camera_, ARV_AUTO_OFF, &error);
        if (error) return io("GainAuto");
      }
      g_clear_error(&error);
      double lo = 0, hi = 0;
      arv_camera_get_gain_bounds(camera_, &lo, &hi, &error);
      if (error) return io("gain bounds");
      if (auto ok = inRange(value, lo, hi, "dB"); !ok) return ok;
      arv_camera_set_gain(camera_, value, &error);
      if (error) return io("Gain");
      return {};
    }
    case Control::kWhiteBalance:  // GenICam has balance ratios, not a colour temperature
    case Control::kPowerLine:
      return unsupported(name(), control);
  }
  return unsupported(name(), control);
}

}  // namespace procam::camera
