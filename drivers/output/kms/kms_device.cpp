#include "kms/kms_device.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <xf86drm.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <utility>

namespace procam::output::kms {
namespace {

template <class T, void (*Free)(T*)>
struct Freer {
  void operator()(T* p) const {
    if (p) Free(p);
  }
};
using Resources = std::unique_ptr<drmModeRes, Freer<drmModeRes, drmModeFreeResources>>;
using ConnectorPtr =
    std::unique_ptr<drmModeConnector, Freer<drmModeConnector, drmModeFreeConnector>>;
using EncoderPtr = std::unique_ptr<drmModeEncoder, Freer<drmModeEncoder, drmModeFreeEncoder>>;
using Props = std::unique_ptr<drmModeObjectProperties,
                              Freer<drmModeObjectProperties, drmModeFreeObjectProperties>>;
using Prop = std::unique_ptr<drmModePropertyRes, Freer<drmModePropertyRes, drmModeFreeProperty>>;
using PlaneRes =
    std::unique_ptr<drmModePlaneRes, Freer<drmModePlaneRes, drmModeFreePlaneResources>>;
using Plane = std::unique_ptr<drmModePlane, Freer<drmModePlane, drmModeFreePlane>>;

std::string errnoText(int e) {
  return std::string(std::strerror(e));
}

}  // namespace

Result<DrmDevice> DrmDevice::open(const std::string& path) {
  std::string node = path;
  if (node.empty()) {
    drmDevicePtr devices[16] = {};
    const int n = drmGetDevices2(0, devices, 16);
    if (n <= 0) {
      return fail(ErrorCode::kNotFound,
                  "no DRM device: the kernel exposes no /dev/dri/card* node (no GPU or display "
                  "driver loaded)");
    }
    for (int i = 0; i < n && node.empty(); ++i) {
      if (!(devices[i]->available_nodes & (1 << DRM_NODE_PRIMARY))) continue;
      const int probe = ::open(devices[i]->nodes[DRM_NODE_PRIMARY], O_RDWR | O_CLOEXEC);
      if (probe < 0) continue;
      Resources res(drmModeGetResources(probe));
      if (res && res->count_connectors > 0) node = devices[i]->nodes[DRM_NODE_PRIMARY];
      ::close(probe);
    }
    drmFreeDevices(devices, n);
    if (node.empty()) {
      return fail(ErrorCode::kNotFound,
                  "no DRM device with display outputs: render-only GPUs cannot drive a projector");
    }
  }
  DrmDevice d;
  d.path_ = node;
  d.fd_ = ::open(node.c_str(), O_RDWR | O_CLOEXEC);
  if (d.fd_ < 0) {
    const int e = errno;
    if (e == ENOENT) return fail(ErrorCode::kNotFound, "no DRM device at " + node);
    return fail(ErrorCode::kIo, "cannot open " + node + ": " + errnoText(e) +
                                    (e == EACCES ? " (add the user to the 'video' group)" : ""));
  }
  if (!drmIsMaster(d.fd_) && drmSetMaster(d.fd_) != 0) {
    return fail(ErrorCode::kIo, "not DRM master on " + node +
                                    ": another process (a display server or console) drives "
                                    "this device; stop it or run from a free virtual terminal");
  }
  if (drmSetClientCap(d.fd_, DRM_CLIENT_CAP_UNIVERSAL_PLANES, 1) != 0) {
    return fail(ErrorCode::kIo, node + ": driver lacks universal planes");
  }
  const bool cap = drmSetClientCap(d.fd_, DRM_CLIENT_CAP_ATOMIC, 1) == 0;
  // Property presence decides together with the cap (kms_select::chooseModesetApi).
  d.atomic_ = cap;
  d.api_reason_ = cap ? "atomic" : "driver refused DRM_CLIENT_CAP_ATOMIC";
  return d;
}

DrmDevice::DrmDevice(DrmDevice&& o) noexcept
    : fd_(std::exchange(o.fd_, -1)),
      path_(std::move(o.path_)),
      atomic_(o.atomic_),
      api_reason_(std::move(o.api_reason_)),
      raw_modes_(std::move(o.raw_modes_)) {}

DrmDevice& DrmDevice::operator=(DrmDevice&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
    path_ = std::move(o.path_);
    atomic_ = o.atomic_;
    api_reason_ = std::move(o.api_reason_);
    raw_modes_ = std::move(o.raw_modes_);
  }
  return *this;
}

DrmDevice::~DrmDevice() {
  if (fd_ >= 0) {
    drmDropMaster(fd_);
    ::close(fd_);
  }
}

Result<std::vector<Connector>> DrmDevice::connectors() {
  Resources res(drmModeGetResources(fd_));
  if (!res) return fail(ErrorCode::kIo, path_ + ": drmModeGetResources: " + errnoText(errno));
  std::vector<Connector> out;
  raw_modes_.clear();
  for (int i = 0; i < res->count_connectors; ++i) {
    ConnectorPtr c(drmModeGetConnector(fd_, res->connectors[i]));
    if (!c) continue;
    Connector k;
    k.id = c->connector_id;
    k.name = connectorTypeName(c->connector_type) + "-" + std::to_string(c->connector_type_id);
    k.connected = c->connection == DRM_MODE_CONNECTED;
    std::vector<drmModeModeInfo> raw;
    for (int m = 0; m < c->count_modes; ++m) {
      const drmModeModeInfo& mi = c->modes[m];
      k.modes.push_back(
          Mode{mi.name, mi.hdisplay, mi.vdisplay,
               refreshHz(mi.clock, mi.htotal, mi.vtotal, (mi.flags & DRM_MODE_FLAG_INTERLACE) != 0,
                         (mi.flags & DRM_MODE_FLAG_DBLSCAN) != 0),
               (mi.type & DRM_MODE_TYPE_PREFERRED) != 0});
      raw.push_back(mi);
    }
    // CRTCs: the one currently driving the connector first, then every possible one.
    for (int e = 0; e < c->count_encoders; ++e) {
      EncoderPtr enc(drmModeGetEncoder(fd_, c->encoders[e]));
      if (!enc) continue;
      const bool current = enc->encoder_id == c->encoder_id && enc->crtc_id != 0;
      if (current) k.crtcs.insert(k.crtcs.begin(), enc->crtc_id);
      for (int j = 0; j < res->count_crtcs; ++j) {
        const uint32_t crtc = res->crtcs[j];
        if ((enc->possible_crtcs & (1u << j)) &&
            std::find(k.crtcs.begin(), k.crtcs.end(), crtc) == k.crtcs.end()) {
          k.crtcs.push_back(crtc);
        }
      }
    }
    out.push_back(std::move(k));
    raw_modes_.push_back(std::move(raw));
  }
  return out;
}

std::vector<std::string> DrmDevice::propertyNames(uint32_t object, uint32_t type) const {
  std::vector<std::string> names;
  Props props(drmModeObjectGetProperties(fd_, object, type));
  if (!props) return names;
  for (uint32_t i = 0; i < props->count_props; ++i) {
    Prop p(drmModeGetProperty(fd_, props->props[i]));
    if (p) names.emplace_back(p->name);
  }
  return names;
}

uint32_t DrmDevice::propertyId(uint32_t object, uint32_t type, const std::string& name) const {
  Props props(drmModeObjectGetProperties(fd_, object, type));
  if (!props) return 0;
  for (uint32_t i = 0; i < props->count_props; ++i) {
    Prop p(drmModeGetProperty(fd_, props->props[i]));
    if (p && name == p->name) return p->prop_id;
  }
  return 0;
}

uint32_t DrmDevice::primaryPlane(uint32_t crtc) const {
  Resources res(drmModeGetResources(fd_));
  PlaneRes planes(drmModeGetPlaneResources(fd_));
  if (!res || !planes) return 0;
  int index = -1;
  for (int j = 0; j < res->count_crtcs; ++j) {
    if (res->crtcs[j] == crtc) index = j;
  }
  if (index < 0) return 0;
  for (uint32_t i = 0; i < planes->count_planes; ++i) {
    Plane plane(drmModeGetPlane(fd_, planes->planes[i]));
    if (!plane || !(plane->possible_crtcs & (1u << index))) continue;
    Props props(drmModeObjectGetProperties(fd_, plane->plane_id, DRM_MODE_OBJECT_PLANE));
    if (!props) continue;
    for (uint32_t k = 0; k < props->count_props; ++k) {
      Prop p(drmModeGetProperty(fd_, props->props[k]));
      if (p && std::strcmp(p->name, "type") == 0 &&
          props->prop_values[k] == DRM_PLANE_TYPE_PRIMARY) {
        return plane->plane_id;
      }
    }
  }
  return 0;
}

}  // namespace procam::output::kms
