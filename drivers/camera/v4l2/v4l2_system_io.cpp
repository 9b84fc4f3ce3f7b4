#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>

#include "camera/v4l2/v4l2_io.hpp"

namespace procam::camera {
namespace {

class SystemV4l2Io final : public V4l2Io {
 public:
  int open(const std::string& path) override {
    const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    return fd >= 0 ? fd : -errno;
  }
  void close(int fd) override { ::close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    int rc;
    do rc = ::ioctl(fd, request, arg);
    while (rc < 0 && errno == EINTR);
    return rc < 0 ? -errno : 0;
  }
  void* mmap(int fd, std::size_t length, int64_t offset, int* error) override {
    void* p = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, off_t(offset));
    if (p != MAP_FAILED) return p;
    *error = errno;
    return nullptr;
  }
  void munmap(void* address, std::size_t length) override { ::munmap(address, length); }
  int poll(int fd, int timeout_ms, bool* hangup) override {
    pollfd p{fd, POLLIN, 0};
    int rc;
    do rc = ::poll(&p, 1, timeout_ms);
    while (rc < 0 && errno == EINTR);
    if (rc < 0) return -errno;
    *hangup = (p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0;
    return rc;
  }
};

}  // namespace

std::unique_ptr<V4l2Io> systemV4l2Io() {
  return std::make_unique<SystemV4l2Io>();
}

}  // namespace procam::camera
