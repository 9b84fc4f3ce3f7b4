#pragma once
// Drivers for device-manager tests: tilt sensors that can be "unplugged"
// (every call returns PROCAM_ENODEV while fake::gone is set) and that expose
// a pipe as poll fd when created with the option fd=pipe.
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <string>

#include "procamd/procam_plugin.h"
#include "registry.hpp"

namespace procam::fake {

inline std::atomic<bool> gone{false};

inline std::string property(const procam_device_desc* d, const char* key) {
  for (size_t i = 0; i < d->n_properties; ++i) {
    if (std::strcmp(d->properties[i].key, key) == 0) return d->properties[i].value;
  }
  return {};
}

struct Tilt {
  int pipe[2] = {-1, -1};  // read end is the poll fd
};

inline int tiltRead(void* self, procam_tilt_sample* out, char* err, size_t len) {
  auto* t = static_cast<Tilt*>(self);
  if (gone) {
    std::snprintf(err, len, "fake sensor unplugged");
    return PROCAM_ENODEV;
  }
  if (t->pipe[0] >= 0) {
    char byte = 0;
    if (::read(t->pipe[0], &byte, 1) != 1) return PROCAM_EAGAIN;
    out->specific_force[0] = byte;  // the byte written identifies the sample
  }
  out->specific_force[2] = 9.81;
  return PROCAM_OK;
}
inline const procam_tilt_ops kTiltOps = {tiltRead};

inline int tiltFd(void* self) {
  return static_cast<Tilt*>(self)->pipe[0];
}
inline void tiltDestroy(void* self) {
  auto* t = static_cast<Tilt*>(self);
  for (int fd : t->pipe) {
    if (fd >= 0) ::close(fd);
  }
  delete t;
}

// Any device udev classified as a tilt sensor; IIO ones score higher.
inline int probeTilt(const procam_device_desc* d) {
  if (property(d, "PROCAM_ROLE") != "tilt") return 0;
  return d->subsystem && std::strcmp(d->subsystem, "iio") == 0 ? 20 : 10;
}
// A weaker driver for the same devices: never chosen while fake-tilt exists.
inline int probeGeneric(const procam_device_desc* d) {
  return property(d, "PROCAM_ROLE") == "tilt" ? 5 : 0;
}

inline int createTilt(const procam_device_desc*, const procam_config* config, procam_device* out,
                      char* err, size_t len) {
  if (gone) {
    std::snprintf(err, len, "no such device");
    return PROCAM_ENODEV;
  }
  auto* t = new Tilt;
  for (size_t i = 0; i < config->n_options; ++i) {
    if (std::strcmp(config->options[i].key, "fd") == 0 &&
        std::strcmp(config->options[i].value, "pipe") == 0 &&
        ::pipe2(t->pipe, O_NONBLOCK | O_CLOEXEC) != 0) {
      delete t;
      return PROCAM_EIO;
    }
  }
  out->family = PROCAM_FAMILY_TILT;
  out->self = t;
  out->poll_fd = tiltFd;
  out->destroy = tiltDestroy;
  out->ops.tilt = &kTiltOps;
  return PROCAM_OK;
}

inline const procam_driver_factory kFactories[] = {
    {PROCAM_FAMILY_TILT, "generic-tilt", "weak match", probeGeneric, createTilt},
    {PROCAM_FAMILY_TILT, "fake-tilt", "test tilt sensor", probeTilt, createTilt},
};

inline plugins::DriverRegistry registry() {
  plugins::DriverRegistry r;
  for (const auto& f : kFactories) r.add(plugins::Driver{&f, "test", nullptr});
  return r;
}

}  // namespace procam::fake
