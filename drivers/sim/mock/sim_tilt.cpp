#include "sim_tilt.hpp"

#include <sys/timerfd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "sim/sensors.hpp"
#include "sim_unplug.hpp"

namespace procam::sim::mock {

SimTiltSensor::SimTiltSensor(std::shared_ptr<SimWorld> world, std::string name)
    : world_(std::move(world)), name_(std::move(name)) {
  for (const auto& spec : world_->scene().tiltSensors()) {
    if (spec.name != name_) continue;
    rate_hz_ = spec.rate_hz;
    unit_ = spec.report_in_g ? kStandardGravity : 1.0;
    gyro_ = spec.gyro.has_value();
  }
}

Result<void> SimTiltSensor::open() {
  const int fd = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (fd < 0) return fail(ErrorCode::kIo, std::string("timerfd: ") + std::strerror(errno));
  timer_.reset(fd);
  next_ = -1;
  armFor(static_cast<long long>(std::floor(world_->now() * rate_hz_)));
  return {};
}

void SimTiltSensor::armFor(long long k) {
  if (!timer_.valid()) return;
  // The world's clock is CLOCK_MONOTONIC from its epoch (sim_world.hpp); a time already
  // past fires at once. Zero would disarm: the earliest is 1 ns.
  const uint64_t ns = std::max<uint64_t>(1, world_->monotonicNs(static_cast<double>(k) / rate_hz_));
  itimerspec spec{};
  spec.it_value.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  spec.it_value.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  (void)::timerfd_settime(timer_.get(), TFD_TIMER_ABSTIME, &spec, nullptr);
}

Result<tilt::TiltSample> SimTiltSensor::read() {
  if (timer_.valid()) {
    // Quiet until re-armed below: a read that fails leaves nothing waiting (an
    // unplugged sensor is reopened, which arms it again).
    uint64_t expirations = 0;
    (void)!::read(timer_.get(), &expirations, sizeof expirations);
  }
  auto gone = unpluggedNow(name_);
  // A malformed variable was refused when the device was created; it changed since.
  if (!gone) return fail(ErrorCode::kInternal, gone.error().message);
  if (*gone)
    return fail(ErrorCode::kNoDevice,
                "'" + name_ + "' is unplugged (" + std::string(kUnplugVariable) + ")");
  // Sample k is taken at k / rate. The oldest unread one is returned; one the FIFO
  // could not hold any more is lost, as on a chip whose reader fell behind.
  const long long newest =
      std::max(0LL, static_cast<long long>(std::floor(world_->now() * rate_hz_)));
  if (next_ < 0) {
    next_ = newest;  // the first read: the newest
  } else if (next_ < newest - kFifoDepth + 1) {
    next_ = newest - kFifoDepth + 1;
  }
  const long long k = std::min(next_, newest);  // none waits: the newest again
  next_ = k + 1;
  armFor(next_);
  const double t = static_cast<double>(k) / rate_hz_;
  auto s = sampleTilt(world_->scene(), name_, t);
  if (!s) return fail(ErrorCode::kIo, s.error().message);
  tilt::TiltSample out;
  out.specific_force = s->value * unit_;
  out.timestamp_ns = static_cast<uint64_t>(std::llround(t * 1e9));
  if (gyro_) {
    // The package's gyroscope, sampled with the same sample (SCENE-FORMAT.md).
    auto w = sampleGyro(world_->scene(), name_, t);
    if (!w) return fail(ErrorCode::kIo, w.error().message);
    out.angular_velocity = w->value;
  }
  return out;
}

}  // namespace procam::sim::mock
