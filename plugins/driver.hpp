#pragma once
// C++ side of the plugin ABI: owning wrappers for drivers, device descriptions
// and created devices. Nothing here throws; failures are procam::Result.
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "procamd/procam_plugin.h"

namespace procam::plugins {

const char* familyName(procam_family family);

// The bits of a family field written by a plugin, read without assuming they
// hold a valid enumerator (loading an out-of-range enum is undefined in C++).
uint32_t rawFamily(const procam_family& field);
bool isKnownFamily(uint32_t raw);
// Parses "camera", "tilt", "tracker", "output".
Result<procam_family> parseFamily(const std::string& text);

// One driver factory and where it came from. `library` keeps a dlopen()ed
// plugin loaded for as long as any driver or device of it is alive.
struct Driver {
  const procam_driver_factory* factory = nullptr;
  std::string origin;  // "static" or the path of the shared object
  std::shared_ptr<void> library;

  procam_family family() const { return factory->family; }
  std::string name() const { return factory->name; }
};

// An owning device description; view() yields the C struct for probe/create.
class DeviceDescription {
 public:
  procam_family family = PROCAM_FAMILY_CAMERA;
  std::string subsystem;
  std::string devnode;
  std::string syspath;
  std::string name;
  std::vector<std::pair<std::string, std::string>> properties;

  std::string property(const std::string& key) const;
  // The returned struct points into this object: keep it alive and unchanged.
  const procam_device_desc& view();

 private:
  std::vector<procam_kv> kv_;
  procam_device_desc desc_{};
};

// A created device; calls the driver's destroy exactly once.
class Device {
 public:
  Device() = default;
  Device(procam_device device, std::shared_ptr<void> library, std::string driver_name);
  Device(Device&& other) noexcept;
  Device& operator=(Device&& other) noexcept;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  ~Device();

  bool valid() const { return device_.destroy != nullptr; }
  procam_family family() const { return device_.family; }
  const std::string& driverName() const { return driver_name_; }
  const procam_device& raw() const { return device_; }
  int pollFd() const;

 private:
  void reset();
  procam_device device_{};
  std::shared_ptr<void> library_;
  std::string driver_name_;
};

// Calls the driver's create() and checks what it returned (family, ops,
// every operation of that family present).
Result<Device> createDevice(const Driver& driver, DeviceDescription& desc,
                            const std::vector<std::pair<std::string, std::string>>& options);

// The devices the driver provides by itself (procam_driver_factory::enumerate)
// for these options; none when the driver has no enumerate. kIo when the driver
// fails, kInvalidInput for a malformed list.
Result<std::vector<DeviceDescription>> enumerateDevices(
    const Driver& driver, const std::vector<std::pair<std::string, std::string>>& options);

// The tracker's own sample rate when its driver reports one.
std::optional<double> trackerRate(const procam_device& device);

// The exposure and gain a camera runs at when its table (version 2 or later) has
// get_settings and the driver answers; fields the driver cannot tell are NaN.
std::optional<procam_camera_settings> cameraSettings(const procam_device& device);

// A tilt driver's sample counts (procam_tilt_ops::get_counts) when its table has them
// (version 2 or later) and it reports them.
std::optional<procam_tilt_counts> tiltCounts(const procam_device& device);
// The samples those counts say the driver rejected, for every reason.
uint64_t rejectedSamples(const procam_tilt_counts& counts);
// The gyroscope's reading with the sample read() last returned (procam_tilt_ops::read_rate)
// when the table has the member and the sensor a gyroscope; nullopt otherwise or when
// a component is not finite. Call it on the thread that called read().
std::optional<procam_rate_sample> tiltRate(const procam_device& device);

}  // namespace procam::plugins
