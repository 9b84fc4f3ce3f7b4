#pragma once
// A DRM device opened for modesetting: the card node, DRM master, client caps, and its
// connectors read into kms_select's plain structs.
#include <xf86drmMode.h>

#include <string>
#include <vector>

#include "core/error.hpp"
#include "kms/kms_select.hpp"

namespace procam::output::kms {

class DrmDevice {
 public:
  // path: "/dev/dri/cardN", or "" for the first primary node that has KMS resources.
  // kNotFound "no DRM device ..." when the system has none; kIo naming the cause when the
  // node cannot be opened or DRM master cannot be obtained.
  static Result<DrmDevice> open(const std::string& path);
  DrmDevice(DrmDevice&& o) noexcept;
  DrmDevice& operator=(DrmDevice&& o) noexcept;
  DrmDevice(const DrmDevice&) = delete;
  DrmDevice& operator=(const DrmDevice&) = delete;
  ~DrmDevice();

  int fd() const { return fd_; }
  const std::string& path() const { return path_; }
  bool atomic() const { return atomic_; }
  const std::string& apiReason() const { return api_reason_; }

  // Connectors with their modes and drivable CRTCs; raw mode lines kept alongside.
  Result<std::vector<Connector>> connectors();
  const drmModeModeInfo& rawMode(size_t connector, size_t mode) const {
    return raw_modes_[connector][mode];
  }
  // Property id by name on a KMS object; 0 when absent.
  uint32_t propertyId(uint32_t object, uint32_t type, const std::string& name) const;
  // Names of an object's properties.
  std::vector<std::string> propertyNames(uint32_t object, uint32_t type) const;
  // Primary plane usable on the CRTC; 0 when none.
  uint32_t primaryPlane(uint32_t crtc) const;

 private:
  DrmDevice() = default;
  int fd_ = -1;
  std::string path_;
  bool atomic_ = false;
  std::string api_reason_;
  std::vector<std::vector<drmModeModeInfo>> raw_modes_;
};

}  // namespace procam::output::kms
