#include "driver.hpp"

#include <array>
#include <cmath>
#include <cstring>

namespace procam::plugins {

const char* familyName(procam_family family) {
  switch (family) {
    case PROCAM_FAMILY_CAMERA:
      return "camera";
    case PROCAM_FAMILY_TILT:
      return "tilt";
    case PROCAM_FAMILY_TRACKER:
      return "tracker";
    case PROCAM_FAMILY_OUTPUT:
      return "output";
  }
  return "unknown";
}

uint32_t rawFamily(const procam_family& field) {
  static_assert(sizeof(procam_family) == sizeof(uint32_t), "the ABI's enums are 32 bits");
  uint32_t raw = 0;
  std::memcpy(&raw, &field, sizeof raw);
  return raw;
}

bool isKnownFamily(uint32_t raw) {
  return raw >= PROCAM_FAMILY_CAMERA && raw <= PROCAM_FAMILY_OUTPUT;
}

Result<procam_family> parseFamily(const std::string& text) {
  for (procam_family f :
       {PROCAM_FAMILY_CAMERA, PROCAM_FAMILY_TILT, PROCAM_FAMILY_TRACKER, PROCAM_FAMILY_OUTPUT}) {
    if (text == familyName(f)) return f;
  }
  return fail(ErrorCode::kInvalidInput,
              "unknown device family '" + text + "' (camera, tilt, tracker, output)");
}

std::string DeviceDescription::property(const std::string& key) const {
  for (const auto& [k, v] : properties) {
    if (k == key) return v;
  }
  return {};
}

const procam_device_desc& DeviceDescription::view() {
  kv_.clear();
  for (const auto& [k, v] : properties) kv_.push_back({k.c_str(), v.c_str()});
  auto cstr = [](const std::string& s) { return s.empty() ? nullptr : s.c_str(); };
  desc_.family = family;
  desc_.subsystem = cstr(subsystem);
  desc_.devnode = cstr(devnode);
  desc_.syspath = cstr(syspath);
  desc_.name = cstr(name);
  desc_.properties = kv_.empty() ? nullptr : kv_.data();
  desc_.n_properties = kv_.size();
  return desc_;
}

Device::Device(procam_device device, std::shared_ptr<void> library, std::string driver_name)
    : device_(device), library_(std::move(library)), driver_name_(std::move(driver_name)) {}

Device::Device(Device&& other) noexcept
    : device_(std::exchange(other.device_, procam_device{})),
      library_(std::move(other.library_)),
      driver_name_(std::move(other.driver_name_)) {}

Device& Device::operator=(Device&& other) noexcept {
  if (this != &other) {
    reset();
    device_ = std::exchange(other.device_, procam_device{});
    library_ = std::move(other.library_);
    driver_name_ = std::move(other.driver_name_);
  }
  return *this;
}

Device::~Device() {
  reset();
}

void Device::reset() {
  if (device_.destroy) device_.destroy(device_.self);
  device_ = procam_device{};
  library_.reset();  // after destroy: the code of destroy lives in the library
}

int Device::pollFd() const {
  return device_.poll_fd ? device_.poll_fd(device_.self) : -1;
}

namespace {

// Every table starts at version 1; a newer table than this daemon knows is
// fine (the daemon only reads the operations it knows).
bool opsComplete(const procam_device& d) {
  switch (d.family) {
    case PROCAM_FAMILY_CAMERA:
      return d.ops.camera && d.ops.camera->version >= 1 && d.ops.camera->get_format &&
             d.ops.camera->set_exposure && d.ops.camera->capture;
    case PROCAM_FAMILY_TILT:
      return d.ops.tilt && d.ops.tilt->version >= 1 && d.ops.tilt->read;
    case PROCAM_FAMILY_TRACKER:
      return d.ops.tracker && d.ops.tracker->version >= 1 && d.ops.tracker->read;
    case PROCAM_FAMILY_OUTPUT:
      return d.ops.output && d.ops.output->version >= 1 && d.ops.output->get_mode &&
             d.ops.output->show;
  }
  return false;
}

procam_config configView(const std::vector<std::pair<std::string, std::string>>& options,
                         std::vector<procam_kv>& kv) {
  kv.clear();
  kv.reserve(options.size());
  for (const auto& [k, v] : options) kv.push_back({k.c_str(), v.c_str()});
  return procam_config{kv.empty() ? nullptr : kv.data(), kv.size()};
}

std::string text(const char* s) {
  return s ? std::string(s) : std::string();
}

}  // namespace

Result<Device> createDevice(const Driver& driver, DeviceDescription& desc,
                            const std::vector<std::pair<std::string, std::string>>& options) {
  std::vector<procam_kv> kv;
  const procam_config config = configView(options, kv);
  procam_device out{};
  std::array<char, 512> err{};
  const int rc = driver.factory->create(&desc.view(), &config, &out, err.data(), err.size() - 1);
  const std::string who = std::string("driver '") + driver.factory->name + "'";
  if (rc != PROCAM_OK) {
    const std::string reason = err[0] ? std::string(err.data()) : "no reason given";
    return fail(ErrorCode::kIo, who + " could not create the device: " + reason + " (code " +
                                    std::to_string(rc) + ")");
  }
  if (!out.destroy) {
    return fail(ErrorCode::kInvalidInput, who + " returned a device without destroy()");
  }
  Device device(out, driver.library, driver.factory->name);  // owns it from here on
  if (rawFamily(out.family) != rawFamily(driver.factory->family)) {
    const uint32_t got = rawFamily(out.family);
    return fail(ErrorCode::kInvalidInput,
                who + " returned a device of family " +
                    (isKnownFamily(got) ? familyName(out.family) : std::to_string(got)) +
                    " for a " + familyName(driver.factory->family) + " factory");
  }
  if (!opsComplete(out)) {
    return fail(ErrorCode::kInvalidInput,
                who + " returned a device with missing " + familyName(out.family) + " operations");
  }
  return device;
}

// Bounds what one plugin may list, so that a broken one cannot flood the daemon.
constexpr size_t kMaxEnumerated = 256;

Result<std::vector<DeviceDescription>> enumerateDevices(
    const Driver& driver, const std::vector<std::pair<std::string, std::string>>& options) {
  std::vector<DeviceDescription> out;
  if (!driver.factory->enumerate) return out;
  std::vector<procam_kv> kv;
  const procam_config config = configView(options, kv);
  const procam_device_desc* list = nullptr;
  size_t n = 0;
  std::array<char, 512> err{};
  const int rc = driver.factory->enumerate(&config, &list, &n, err.data(), err.size() - 1);
  const std::string who = std::string("driver '") + driver.factory->name + "'";
  if (rc != PROCAM_OK) {
    const std::string reason = err[0] ? std::string(err.data()) : "no reason given";
    return fail(ErrorCode::kIo, who + " could not list its devices: " + reason);
  }
  if (n > kMaxEnumerated || (n > 0 && !list)) {
    return fail(ErrorCode::kInvalidInput, who + " listed " + std::to_string(n) +
                                              " devices (at most " +
                                              std::to_string(kMaxEnumerated) + ")");
  }
  for (size_t i = 0; i < n; ++i) {
    const procam_device_desc& d = list[i];
    if (rawFamily(d.family) != rawFamily(driver.factory->family)) {
      return fail(ErrorCode::kInvalidInput,
                  who + " listed a device of another family than its own");
    }
    DeviceDescription desc;
    desc.family = d.family;
    desc.subsystem = text(d.subsystem);
    desc.devnode = text(d.devnode);
    desc.syspath = text(d.syspath);
    desc.name = text(d.name);
    if (desc.name.empty())
      return fail(ErrorCode::kInvalidInput, who + " listed a device without a name");
    for (size_t k = 0; k < d.n_properties && d.properties; ++k) {
      desc.properties.emplace_back(text(d.properties[k].key), text(d.properties[k].value));
    }
    out.push_back(std::move(desc));
  }
  return out;
}

}  // namespace procam::plugins

namespace procam::plugins {

std::optional<double> trackerRate(const procam_device& d) {
  if (d.family != PROCAM_FAMILY_TRACKER || !d.ops.tracker || !d.ops.tracker->get_rate) {
    return std::nullopt;
  }
  double hz = 0;
  if (d.ops.tracker->get_rate(d.self, &hz) != PROCAM_OK || !std::isfinite(hz) || hz <= 0 ||
      hz > 10000) {
    return std::nullopt;
  }
  return hz;
}

// get_settings came with version 2 of the camera table.
constexpr uint32_t kCameraSettingsVersion = 2;

std::optional<procam_camera_settings> cameraSettings(const procam_device& d) {
  if (d.family != PROCAM_FAMILY_CAMERA || !d.ops.camera ||
      d.ops.camera->version < kCameraSettingsVersion || !d.ops.camera->get_settings) {
    return std::nullopt;
  }
  procam_camera_settings s{std::nan(""), std::nan(""), 0};
  if (d.ops.camera->get_settings(d.self, &s) != PROCAM_OK) return std::nullopt;
  return s;
}

// get_counts came with version 2 of the tilt table: a version 1 table ends before it.
constexpr uint32_t kTiltCountsVersion = 2;

std::optional<procam_tilt_counts> tiltCounts(const procam_device& d) {
  if (d.family != PROCAM_FAMILY_TILT || !d.ops.tilt || d.ops.tilt->version < kTiltCountsVersion ||
      !d.ops.tilt->get_counts) {
    return std::nullopt;
  }
  procam_tilt_counts c{};
  if (d.ops.tilt->get_counts(d.self, &c) != PROCAM_OK) return std::nullopt;
  return c;
}

// read_rate came with version 3 of the tilt table.
constexpr uint32_t kTiltRateVersion = 3;

std::optional<procam_rate_sample> tiltRate(const procam_device& d) {
  if (d.family != PROCAM_FAMILY_TILT || !d.ops.tilt || d.ops.tilt->version < kTiltRateVersion ||
      !d.ops.tilt->read_rate) {
    return std::nullopt;
  }
  procam_rate_sample r{};
  char err[128] = {0};
  if (d.ops.tilt->read_rate(d.self, &r, err, sizeof err - 1) != PROCAM_OK) return std::nullopt;
  for (double w : r.angular_velocity) {
    if (!std::isfinite(w)) return std::nullopt;
  }
  return r;
}

uint64_t rejectedSamples(const procam_tilt_counts& c) {
  return c.not_finite + c.out_of_range + c.stuck + c.bad_norm;
}

}  // namespace procam::plugins
