#pragma once
// Drivers for device-manager tests: tilt sensors that can be "unplugged"
// (every call returns PROCAM_ENODEV while fake::gone is set) and that expose
// a pipe as poll fd when created with the option fd=pipe; slow trackers
// whose read blocks while fake::hold is set (as a blob search would), with
// counters of the reads running at once; and cameras without a poll fd whose
// capture fails with PROCAM_ENODEV while fake::camera_gone is set (a GigE
// camera that died: nothing else tells).
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>

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

inline bool hasOption(const procam_config* c, const char* key, const char* value) {
  for (size_t i = 0; i < c->n_options; ++i) {
    if (std::strcmp(c->options[i].key, key) == 0 && std::strcmp(c->options[i].value, value) == 0) {
      return true;
    }
  }
  return false;
}

inline void closePipe(int (&pipe)[2]) {
  for (int fd : pipe) {
    if (fd >= 0) ::close(fd);
  }
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
inline const procam_tilt_ops kTiltOps = {PROCAM_TILT_OPS_VERSION, tiltRead, nullptr, nullptr};

inline int tiltFd(void* self) {
  return static_cast<Tilt*>(self)->pipe[0];
}
inline void tiltDestroy(void* self) {
  auto* t = static_cast<Tilt*>(self);
  closePipe(t->pipe);
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
  if (hasOption(config, "fd", "pipe") && ::pipe2(t->pipe, O_NONBLOCK | O_CLOEXEC) != 0) {
    delete t;
    return PROCAM_EIO;
  }
  out->family = PROCAM_FAMILY_TILT;
  out->self = t;
  out->poll_fd = tiltFd;
  out->destroy = tiltDestroy;
  out->ops.tilt = &kTiltOps;
  return PROCAM_OK;
}

// Slow trackers. A read started while `hold` is set blocks until it is
// cleared (at most 10 s, so a failing test cannot hang).
inline std::atomic<bool> hold{false};
inline std::atomic<int> reads_running{0};       // over every tracker
inline std::atomic<int> most_reads_running{0};  // the peak of reads_running
inline std::atomic<int> destroyed_mid_read{0};  // destroy() while a read of it ran
inline std::atomic<int> trackers_destroyed{0};

struct Tracker {
  int pipe[2] = {-1, -1};     // option fd=readable: a pipe that stays readable
  std::atomic<int> reads{0};  // reads started
  std::atomic<bool> in_read{false};
};

inline int trackerRead(void* self, procam_pose_sample* out, char* err, size_t len) {
  auto* t = static_cast<Tracker*>(self);
  t->in_read = true;
  const int n = ++t->reads;
  const int running = ++reads_running;
  for (int peak = most_reads_running; running > peak;) {
    if (most_reads_running.compare_exchange_weak(peak, running)) break;
  }
  const auto limit = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (hold && std::chrono::steady_clock::now() < limit) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  --reads_running;
  t->in_read = false;
  if (gone) {
    std::snprintf(err, len, "fake tracker unplugged");
    return PROCAM_ENODEV;
  }
  out->position[0] = n;  // the read's number identifies the sample
  out->orientation[0] = 1;
  out->timestamp_ns = static_cast<uint64_t>(n);
  return PROCAM_OK;
}
inline const procam_tracker_ops kTrackerOps = {PROCAM_TRACKER_OPS_VERSION, trackerRead, nullptr};

inline int trackerFd(void* self) {
  return static_cast<Tracker*>(self)->pipe[0];
}
inline void trackerDestroy(void* self) {
  auto* t = static_cast<Tracker*>(self);
  if (t->in_read) ++destroyed_mid_read;
  ++trackers_destroyed;
  closePipe(t->pipe);
  delete t;
}

inline int probeTracker(const procam_device_desc* d) {
  return property(d, "PROCAM_ROLE") == "tracker" ? 10 : 0;
}

inline int createTracker(const procam_device_desc*, const procam_config* config, procam_device* out,
                         char* err, size_t len) {
  if (gone) {
    std::snprintf(err, len, "no such device");
    return PROCAM_ENODEV;
  }
  auto* t = new Tracker;
  if (hasOption(config, "fd", "readable") &&
      (::pipe2(t->pipe, O_NONBLOCK | O_CLOEXEC) != 0 || ::write(t->pipe[1], "x", 1) != 1)) {
    closePipe(t->pipe);
    delete t;
    return PROCAM_EIO;
  }
  out->family = PROCAM_FAMILY_TRACKER;
  out->self = t;
  out->poll_fd = trackerFd;
  out->destroy = trackerDestroy;
  out->ops.tracker = &kTrackerOps;
  return PROCAM_OK;
}

// Cameras. Only capture() notices that the camera is gone: the format is
// answered from memory, as real drivers do.
inline std::atomic<bool> camera_gone{false};
inline std::atomic<int> captures{0};  // over every camera
inline std::atomic<int> cameras_destroyed{0};
inline std::atomic<std::thread::id> camera_destroyed_on{};

struct Camera {
  uint64_t frames = 0;
  uint8_t pixels[8] = {};
};

inline int cameraFormat(void*, uint32_t* w, uint32_t* h, procam_pixel_format* f) {
  *w = 4;
  *h = 2;
  *f = PROCAM_PIXEL_GRAY8;
  return PROCAM_OK;
}
inline int cameraExposure(void*, double, char*, size_t) {
  return PROCAM_ENOTSUP;
}
inline int cameraCapture(void* self, int, procam_image* out, char* err, size_t len) {
  ++captures;
  if (camera_gone) {
    std::snprintf(err, len, "fake camera stopped answering");
    return PROCAM_ENODEV;
  }
  auto* c = static_cast<Camera*>(self);
  out->width = 4;
  out->height = 2;
  out->stride = 4;
  out->format = PROCAM_PIXEL_GRAY8;
  out->data = c->pixels;
  out->timestamp_ns = ++c->frames;
  return PROCAM_OK;
}
inline const procam_camera_ops kCameraOps = {
    PROCAM_CAMERA_OPS_VERSION, cameraFormat, cameraExposure, cameraCapture, nullptr, nullptr};

inline int noFd(void*) {
  return -1;
}
inline void cameraDestroy(void* self) {
  camera_destroyed_on = std::this_thread::get_id();
  ++cameras_destroyed;
  delete static_cast<Camera*>(self);
}

// Chosen by name only: udev's cameras stay unclaimed in the tests that expect so.
inline int probeCamera(const procam_device_desc*) {
  return 0;
}

inline int createCamera(const procam_device_desc*, const procam_config*, procam_device* out,
                        char* err, size_t len) {
  if (camera_gone) {
    std::snprintf(err, len, "no answer from the camera");
    return PROCAM_ENODEV;
  }
  out->family = PROCAM_FAMILY_CAMERA;
  out->self = new Camera;
  out->poll_fd = noFd;
  out->destroy = cameraDestroy;
  out->ops.camera = &kCameraOps;
  return PROCAM_OK;
}

// The same camera with a liveness check: the daemon checks it instead of capturing.
inline std::atomic<int> checks{0};
inline int cameraCheck(void*, char* err, size_t len) {
  ++checks;
  if (camera_gone) {
    std::snprintf(err, len, "fake camera stopped answering its checks");
    return PROCAM_ENODEV;
  }
  return PROCAM_OK;
}
inline const procam_camera_ops kCheckedCameraOps = {
    PROCAM_CAMERA_OPS_VERSION, cameraFormat, cameraExposure, cameraCapture, cameraCheck, nullptr};
inline int createCheckedCamera(const procam_device_desc* d, const procam_config* c,
                               procam_device* out, char* err, size_t len) {
  const int rc = createCamera(d, c, out, err, len);
  if (rc == PROCAM_OK) out->ops.camera = &kCheckedCameraOps;
  return rc;
}

inline const procam_driver_factory kFactories[] = {
    {PROCAM_FAMILY_TILT, "generic-tilt", "weak match", probeGeneric, createTilt, nullptr},
    {PROCAM_FAMILY_TILT, "fake-tilt", "test tilt sensor", probeTilt, createTilt, nullptr},
    {PROCAM_FAMILY_TRACKER, "slow-tracker", "test tracker", probeTracker, createTracker, nullptr},
    {PROCAM_FAMILY_CAMERA, "silent-camera", "test camera without a poll fd", probeCamera,
     createCamera, nullptr},
    {PROCAM_FAMILY_CAMERA, "checked-camera", "test camera with a liveness check", probeCamera,
     createCheckedCamera, nullptr},
};

inline plugins::DriverRegistry registry() {
  plugins::DriverRegistry r;
  for (const auto& f : kFactories) r.add(plugins::Driver{&f, "test", nullptr});
  return r;
}

}  // namespace procam::fake
