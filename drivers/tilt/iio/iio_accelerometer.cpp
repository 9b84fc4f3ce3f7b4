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

Result<void> IioAccelerometer::open() {
  if (open_) return {};
  for (const char* a : kAxes)
    if (!hasAttribute(std::string("in_accel_") + a + "_raw"))
      return fail(ErrorCode::kNotFound, config_.device_dir + ": no in_accel_" + a + "_raw");
  for (int a = 0; a < 3; ++a) {
    const std::string axis = std::string("in_accel_") + kAxes[a];
    const std::string scale = hasAttribute(axis + "_scale") ? axis + "_scale" : "in_accel_scale";
    auto s = attribute(scale);
    if (!s) return tl::unexpected(s.error());
    auto sv = toNumber(*s, scale);
    if (!sv) return tl::unexpected(sv.error());
    scale_[a] = *sv;
    offset_[a] = 0;
    for (const std::string& off : {axis + "_offset", std::string("in_accel_offset")}) {
      if (!hasAttribute(off)) continue;
      auto o = attribute(off);
      if (!o) return tl::unexpected(o.error());
      auto ov = toNumber(*o, off);
      if (!ov) return tl::unexpected(ov.error());
      offset_[a] = *ov;
      break;
    }
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
    const bool wanted = ch == "accel_x" || ch == "accel_y" || ch == "accel_z" || ch == "timestamp";
    if (wanted)
      if (auto w = setAttribute("scan_elements/" + file, "1"); !w) return w;
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
  int axes = 0;
  for (const auto& c : channels_) axes += c.name.rfind("accel_", 0) == 0;
  if (axes != 3) return fail(ErrorCode::kNotFound, "buffer does not carry the three accel axes");
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

Result<TiltSample> IioAccelerometer::read() {
  if (!open_) return fail(ErrorCode::kIo, "iio: not open");
  TiltSample s;
  if (fd_ < 0) {
    for (int a = 0; a < 3; ++a) {
      const std::string file = std::string("in_accel_") + kAxes[a] + "_raw";
      auto raw = attribute(file);
      if (!raw) return tl::unexpected(raw.error());
      auto v = toNumber(*raw, file);
      if (!v) return tl::unexpected(v.error());
      s.specific_force(a) = (*v + offset_[a]) * scale_[a];
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
  for (const auto& c : channels_) {
    const std::int64_t v = c.type.decode(record.data() + c.offset);
    if (c.name == "timestamp") s.timestamp_ns = std::uint64_t(v);
    for (int a = 0; a < 3; ++a)
      if (c.name == std::string("accel_") + kAxes[a])
        s.specific_force(a) = (double(v) + offset_[a]) * scale_[a];
  }
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
