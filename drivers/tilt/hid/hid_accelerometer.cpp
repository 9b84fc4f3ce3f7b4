#include "tilt/hid/hid_accelerometer.hpp"

#include <fcntl.h>
#include <linux/hidraw.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace procam::tilt {

Result<std::unique_ptr<HidrawTransport>> HidrawTransport::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
  return std::unique_ptr<HidrawTransport>(new HidrawTransport(fd, path));
}

HidrawTransport::~HidrawTransport() {
  if (fd_ >= 0) ::close(fd_);
}

Result<std::vector<std::uint8_t>> HidrawTransport::reportDescriptor() {
  int size = 0;
  if (ioctl(fd_, HIDIOCGRDESCSIZE, &size) < 0)
    return fail(ErrorCode::kIo, path_ + ": HIDIOCGRDESCSIZE: " + std::strerror(errno));
  hidraw_report_descriptor desc{};
  desc.size = std::uint32_t(size);
  if (ioctl(fd_, HIDIOCGRDESC, &desc) < 0)
    return fail(ErrorCode::kIo, path_ + ": HIDIOCGRDESC: " + std::strerror(errno));
  return std::vector<std::uint8_t>(desc.value, desc.value + desc.size);
}

Result<std::vector<std::uint8_t>> HidrawTransport::readReport(int timeout_ms) {
  pollfd pfd{fd_, POLLIN, 0};
  const int ready = ::poll(&pfd, 1, timeout_ms);
  if (ready < 0) return fail(ErrorCode::kIo, path_ + ": poll: " + std::strerror(errno));
  if (ready == 0) return fail(ErrorCode::kNotFound, path_ + ": no report within the timeout");
  std::vector<std::uint8_t> buf(HID_MAX_DESCRIPTOR_SIZE);
  const ssize_t n = ::read(fd_, buf.data(), buf.size());
  if (n < 0 && errno == EAGAIN) return fail(ErrorCode::kNotFound, path_ + ": no report");
  if (n < 0) return fail(ErrorCode::kIo, path_ + ": read: " + std::strerror(errno));
  buf.resize(std::size_t(n));
  return buf;
}

Result<void> HidAccelerometer::open() {
  if (open_) return {};
  auto bytes = transport_->reportDescriptor();
  if (!bytes) return tl::unexpected(bytes.error());
  auto desc = parseHidDescriptor(*bytes);
  if (!desc) return tl::unexpected(desc.error());
  auto fields = findAccelerometer(*desc);
  if (!fields) return tl::unexpected(fields.error());
  fields_ = *fields;
  // A gyrometer this driver cannot read (another unit, axes split over reports) leaves
  // the accelerometer as it is, without a rate.
  gyro_.reset();
  if (auto gyro = findGyrometer(*desc)) gyro_ = *gyro;
  last_rate_.reset();
  uses_report_ids_ = desc->uses_report_ids;
  open_ = true;
  return {};
}

void HidAccelerometer::readGyro(std::span<const std::uint8_t> data, std::uint64_t now_ns) {
  Vec3 rate;
  for (int a = 0; a < 3; ++a) {
    const HidField& f = gyro_->axis[a];
    auto v = f.extract(data);
    // A short or out-of-range report says nothing about the rate: none until a good one.
    if (!v || *v < f.logical_min || *v > f.logical_max) {
      last_rate_.reset();
      return;
    }
    rate(a) = double(*v) * gyro_->scale;
  }
  last_rate_ = rate;
  last_rate_ns_ = now_ns;
}

Result<TiltSample> HidAccelerometer::read() {
  if (!open_) return fail(ErrorCode::kIo, "hid: not open");
  // A sensor hub interleaves reports of several sensors: the gyrometer's are kept for
  // the next accelerometer sample, the others skipped.
  for (int attempt = 0; attempt < 16; ++attempt) {
    auto report = transport_->readReport(timeout_ms_);
    if (!report) return tl::unexpected(report.error());
    std::span<const std::uint8_t> data(*report);
    const std::uint64_t now = monotonicNs();
    const std::uint8_t id = uses_report_ids_ && !data.empty() ? data[0] : 0;
    if (uses_report_ids_) {
      if (data.empty()) continue;
      data = data.subspan(1);
    }
    if (gyro_ && id == gyro_->axis[0].report_id) readGyro(data, now);
    if (id != fields_.axis[0].report_id) continue;
    TiltSample s;
    s.timestamp_ns = now;
    if (last_rate_ && now - last_rate_ns_ <= kGyroFreshNs) s.angular_velocity = last_rate_;
    for (int a = 0; a < 3; ++a) {
      const HidField& f = fields_.axis[a];
      auto v = f.extract(data);
      if (!v) return fail(ErrorCode::kIo, "hid: report too short");
      if (*v < f.logical_min || *v > f.logical_max)
        return fail(ErrorCode::kInvalidInput, "hid: value outside the logical range");
      s.specific_force(a) = double(*v) * fields_.scale;
    }
    return s;
  }
  return fail(ErrorCode::kNotFound, "hid: no accelerometer report among the last 16");
}

}  // namespace procam::tilt
