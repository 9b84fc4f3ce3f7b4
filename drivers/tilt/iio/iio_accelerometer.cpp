#include "tilt/iio/iio_accelerometer.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

namespace procam::tilt {
namespace {

constexpr const char* kAxes[3] = {"x", "y", "z"};

Result<double> toNumber(const std::string& text, const std::string& what) {
  std::istringstream in(text);
  double v = 0;
  if (!(in >> v) || !std::isfinite(v)) return fail(ErrorCode::kParse, what + ": '" + text + "'");
  return v;
}

}  // namespace

Result<std::string> IioAccelerometer::attribute(const std::string& rel) const {
  const std::string path = config_.device_dir + "/" + rel;
  std::ifstream in(path);
  if (!in) return fail(ErrorCode::kIo, path + ": cannot read");
  std::string text;
  std::getline(in, text);
  return text;
}

Result<void> IioAccelerometer::setAttribute(const std::string& rel,
                                            const std::string& value) const {
  const std::string path = config_.device_dir + "/" + rel;
  std::ofstream out(path);
  if (!out || !(out << value << "\n") || !out.flush())
    return fail(ErrorCode::kIo, path + ": cannot write");
  return {};
}

bool IioAccelerometer::hasAttribute(const std::string& rel) const {
  std::error_code ec;
  return std::filesystem::exists(config_.device_dir + "/" + rel, ec);
}

Result<std::pair<double, double>> IioAccelerometer::scaleAndOffset(const std::string& type,
                                                                   int axis) const {
  const std::string channel = "in_" + type + "_" + kAxes[axis];
  const std::string shared = "in_" + type;
  const std::string scale =
      hasAttribute(channel + "_scale") ? channel + "_scale" : shared + "_scale";
  auto s = attribute(scale);
  if (!s) return tl::unexpected(s.error());
  auto sv = toNumber(*s, scale);
  if (!sv) return tl::unexpected(sv.error());
  for (const std::string& off : {channel + "_offset", shared + "_offset"}) {
    if (!hasAttribute(off)) continue;
    auto o = attribute(off);
    if (!o) return tl::unexpected(o.error());
    auto ov = toNumber(*o, off);
    if (!ov) return tl::unexpected(ov.error());
    return std::pair{*sv, *ov};
  }
  return std::pair{*sv, 0.0};
}

Result<void> IioAccelerometer::open() {
  if (open_) return {};
  for (const char* a : kAxes)
    if (!hasAttribute(std::string("in_accel_") + a + "_raw"))
      return fail(ErrorCode::kNotFound, config_.device_dir + ": no in_accel_" + a + "_raw");
  for (int a = 0; a < 3; ++a) {
    auto so = scaleAndOffset("accel", a);
    if (!so) return tl::unexpected(so.error());
    std::tie(scale_[a], offset_[a]) = *so;
  }
  // A gyroscope on the same device (a combined IMU): its three anglvel channels, rad/s.
  gyro_ = true;
  for (const char* a : kAxes)
    gyro_ = gyro_ && hasAttribute(std::string("in_anglvel_") + a + "_raw");
  // The gyroscope is extra: one whose scale cannot be read leaves the accelerometer alone.
  for (int a = 0; gyro_ && a < 3; ++a) {
    auto so = scaleAndOffset("anglvel", a);
    if (so) std::tie(gyro_scale_[a], gyro_offset_[a]) = *so;
    gyro_ = so.has_value();
  }
  for (const char* freq : {"in_accel_sampling_frequency", "sampling_frequency"}) {
    if (!hasAttribute(freq)) continue;
    if (config_.sampling_hz)
      if (auto w = setAttribute(freq, std::to_string(*config_.sampling_hz)); !w) return w;
    auto f = attribute(freq);
    if (f)
      if (auto fv = toNumber(*f, freq)) sampling_hz_ = *fv;
    break;
  }
  if (config_.buffered && hasAttribute("scan_elements"))
    if (auto b = openBuffer(); !b) return b;
  open_ = true;
  return {};
}

Result<void> IioAccelerometer::openBuffer() {
  channels_.clear();
  // Enable the three axes and the timestamp; every other channel's current state is
  // respected, since the record layout depends on all enabled channels.
  std::error_code ec;
  for (const auto& entry :
       std::filesystem::directory_iterator(config_.device_dir + "/scan_elements", ec)) {
    const std::string file = entry.path().filename().string();
    if (file.size() < 7 || file.rfind("in_", 0) != 0 || file.substr(file.size() - 3) != "_en")
      continue;
    const std::string ch = file.substr(3, file.size() - 6);
    const bool wanted = ch == "accel_x" || ch == "accel_y" || ch == "accel_z" ||
                        ch == "timestamp" ||
                        (gyro_ && (ch == "anglvel_x" || ch == "anglvel_y" || ch == "anglvel_z"));
    const bool rate = ch.rfind("anglvel_", 0) == 0;
    if (wanted) {
      auto w = setAttribute("scan_elements/" + file, "1");
      if (!w && !rate) return w;  // the gyroscope's channels are extra
    }
    auto en = attribute("scan_elements/" + file);
    if (!en) return tl::unexpected(en.error());
    if (en->empty() || (*en)[0] != '1') continue;
    IioScanChannel c;
    c.name = ch;
    auto idx = attribute("scan_elements/in_" + ch + "_index");
    auto type = attribute("scan_elements/in_" + ch + "_type");
    if (!idx || !type) return fail(ErrorCode::kIo, "scan element " + ch + " lacks index or type");
    auto iv = toNumber(*idx, "index");
    auto tv = parseIioScanType(*type);
    if (!iv) return tl::unexpected(iv.error());
    if (!tv) return tl::unexpected(tv.error());
    c.index = int(*iv);
    c.type = *tv;
    channels_.push_back(c);
  }
  if (ec) return fail(ErrorCode::kIo, config_.device_dir + "/scan_elements: " + ec.message());
  record_size_ = layoutIioRecord(channels_);
  int axes = 0, rates = 0;
  for (const auto& c : channels_) {
    axes += c.name.rfind("accel_", 0) == 0;
    rates += c.name.rfind("anglvel_", 0) == 0;
  }
  if (axes != 3) return fail(ErrorCode::kNotFound, "buffer does not carry the three accel axes");
  gyro_ = gyro_ && rates == 3;  // a buffer without them: the accelerometer alone
  if (auto w = setAttribute("buffer/length", std::to_string(config_.buffer_length)); !w) return w;
  if (auto w = setAttribute("buffer/enable", "1"); !w) return w;
  std::string node = config_.device_node;
  if (node.empty()) node = "/dev/" + std::filesystem::path(config_.device_dir).filename().string();
  fd_ = ::open(node.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const std::string err = std::strerror(errno);
    (void)setAttribute("buffer/enable", "0");
    return fail(ErrorCode::kIo, node + ": " + err);
  }
  return {};
}

Result<Vec3> IioAccelerometer::polledChannels(const char* type, const std::array<double, 3>& scale,
                                              const std::array<double, 3>& offset) const {
  Vec3 out;
  for (int a = 0; a < 3; ++a) {
    const std::string file = std::string("in_") + type + "_" + kAxes[a] + "_raw";
    auto raw = attribute(file);
    if (!raw) return tl::unexpected(raw.error());
    auto v = toNumber(*raw, file);
    if (!v) return tl::unexpected(v.error());
    out(a) = (*v + offset[a]) * scale[a];
  }
  return out;
}

Result<TiltSample> IioAccelerometer::read() {
  if (!open_) return fail(ErrorCode::kIo, "iio: not open");
  TiltSample s;
  if (fd_ < 0) {
    auto force = polledChannels("accel", scale_, offset_);
    if (!force) return tl::unexpected(force.error());
    s.specific_force = *force;
    if (gyro_) {
      // A gyroscope reading that fails leaves the sample without one, not the sample.
      auto rate = polledChannels("anglvel", gyro_scale_, gyro_offset_);
      if (rate) s.angular_velocity = *rate;
    }
    s.timestamp_ns = monotonicNs();
    return s;
  }
  pollfd pfd{fd_, POLLIN, 0};
  const int ready = ::poll(&pfd, 1, config_.poll_timeout_ms);
  if (ready < 0) return fail(ErrorCode::kIo, std::string("iio poll: ") + std::strerror(errno));
  if (ready == 0) return fail(ErrorCode::kNotFound, "iio: no record within the timeout");
  std::vector<std::uint8_t> record(record_size_);
  const ssize_t n = ::read(fd_, record.data(), record.size());
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
    return fail(ErrorCode::kNotFound, "iio: no record available");
  if (n < 0) return fail(ErrorCode::kIo, std::string("iio read: ") + std::strerror(errno));
  if (n == 0) return fail(ErrorCode::kNotFound, "iio: no record available");
  if (std::size_t(n) != record.size()) return fail(ErrorCode::kIo, "iio: short record");
  s.timestamp_ns = monotonicNs();
  Vec3 w = Vec3::Zero();
  for (const auto& c : channels_) {
    const std::int64_t v = c.type.decode(record.data() + c.offset);
    if (c.name == "timestamp") s.timestamp_ns = std::uint64_t(v);
    for (int a = 0; a < 3; ++a) {
      if (c.name == std::string("accel_") + kAxes[a])
        s.specific_force(a) = (double(v) + offset_[a]) * scale_[a];
      if (c.name == std::string("anglvel_") + kAxes[a])
        w(a) = (double(v) + gyro_offset_[a]) * gyro_scale_[a];
    }
  }
  if (gyro_) s.angular_velocity = w;
  return s;
}

void IioAccelerometer::close() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
    (void)setAttribute("buffer/enable", "0");
  }
  open_ = false;
}

}  // namespace procam::tilt
