#pragma once
// Shared-memory frames: a sealed memfd another process fills, handed to procamd
// over the control socket (SCM_RIGHTS), so any application's output can be shown
// through the keystone warp.
//
// Layout (all integers little-endian, as the host): a 4 KiB header page, then two
// frame buffers of `frameBytes` each, every buffer starting on a 64-byte boundary.
// The producer writes the buffer that is not `front`, bumping that buffer's
// sequence to odd before and to even after writing, then publishes it as `front`
// and increments `frames`. The reader copies `front` and keeps the copy only if
// the buffer's sequence was even and unchanged across the copy (a seqlock per
// buffer), so a frame overwritten while being copied is never shown.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>

#include "content_source.hpp"

namespace procam::content {

inline constexpr uint32_t kShmMagic = 0x4d48'5350;  // "PSHM"
inline constexpr uint32_t kShmVersion = 1;
inline constexpr size_t kShmHeaderBytes = 4096;
// What procamd requires before it maps a memfd (F_SEAL_WRITE must not be set).
inline constexpr int kShmRequiredSeals = 0x0001 | 0x0002 | 0x0004;  // SEAL|SHRINK|GROW

struct ShmHeader {
  uint32_t magic;
  uint32_t version;
  uint32_t width;
  uint32_t height;
  uint32_t format;  // 0 rgb8, 1 rgba8
  uint32_t stride;  // bytes per row (width * bytes per pixel)
  uint64_t buffer_offset[2];
  // Only ever accessed through std::atomic_ref.
  uint64_t buffer_sequence[2];
  uint64_t front;
  uint64_t frames;
};
static_assert(sizeof(ShmHeader) <= kShmHeaderBytes);

size_t shmFrameBytes(cv::Size size, PixelFormat format);
// Header page plus two buffers.
size_t shmTotalBytes(cv::Size size, PixelFormat format);
// Writes the header for the given frame size into `memory` (both buffers black).
void initShmHeader(std::span<std::byte> memory, cv::Size size, PixelFormat format);

// The reading side over mapped memory (not owned).
class ShmFrameReader {
 public:
  ShmFrameReader(const std::byte* memory, cv::Size size, PixelFormat format);
  // The number of frames published so far.
  uint64_t published() const;
  // Copies the newest whole frame into `out` (CV_8UC3/4 of the frame size); false
  // when the producer was writing it (retried up to `attempts` times). The hook
  // runs between the copy and the check (tests use it to overwrite the buffer).
  bool copyNewest(cv::Mat& out, int attempts = 4, const std::function<void()>& after_copy = {});

 private:
  const std::byte* memory_;
  cv::Size size_;
  PixelFormat format_;
};

// The producing side: creates the memfd, seals it, and publishes frames. Used by
// applications (and tests) that feed procamd.
class ShmFrameProducer {
 public:
  static Result<ShmFrameProducer> create(cv::Size size, PixelFormat format);
  ShmFrameProducer(ShmFrameProducer&&) noexcept;
  ShmFrameProducer& operator=(ShmFrameProducer&&) = delete;
  ~ShmFrameProducer();

  int fd() const { return fd_; }
  std::byte* memory() const { return memory_; }
  // Copies `pixels` (rows packed, the producer's size and format) into the back
  // buffer and makes it the front one.
  void publish(const uint8_t* pixels);
  // The two halves of publish(), for tests that stop in between.
  uint8_t* beginWrite();
  void endWrite();

 private:
  ShmFrameProducer(int fd, std::byte* memory, size_t bytes, cv::Size size, PixelFormat format);
  int fd_ = -1;
  std::byte* memory_ = nullptr;
  size_t bytes_ = 0;
  cv::Size size_;
  PixelFormat format_ = PixelFormat::kRgba8;
  uint64_t writing_ = 0;
};

// Takes ownership of `fd`: checks it is a memfd sealed against shrinking, growing
// and further sealing, large enough for two frames of the size and format, and
// that its header agrees; maps it read-only. kInvalidInput with a message naming
// what is wrong otherwise (the fd is closed either way once this returns, unless
// it is kept by the source).
Result<std::unique_ptr<ContentSource>> openSharedFrames(int fd, cv::Size size, PixelFormat format);

}  // namespace procam::content
