#pragma once
// The kernel calls of the V4L2 camera behind one interface, so that tests drive format
// negotiation and the buffer state machine with a fake device. Every call returns a
// negative errno on failure, never throws.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace procam::camera {

class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int open(const std::string& path) = 0;  // a descriptor, or -errno
  virtual void close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;  // 0 or -errno
  // The mapping, or nullptr with `*error` = errno.
  virtual void* mmap(int fd, std::size_t length, int64_t offset, int* error) = 0;
  virtual void munmap(void* address, std::size_t length) = 0;
  // poll(POLLIN): > 0 ready, 0 timed out, -errno; `*hangup` when POLLERR/POLLHUP came.
  virtual int poll(int fd, int timeout_ms, bool* hangup) = 0;
};

// The real calls (open O_RDWR | O_NONBLOCK | O_CLOEXEC, ioctl retried on EINTR).
std::unique_ptr<V4l2Io> systemV4l2Io();

}  // namespace procam::camera
