#include "shm_frames.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/unique_fd.hpp"

namespace procam::content {

using procam::UniqueFd;

namespace {

static_assert(kShmRequiredSeals == (F_SEAL_SEAL | F_SEAL_SHRINK | F_SEAL_GROW));

constexpr int kMaxSide = 16384;
constexpr size_t kBufferAlign = 64;

size_t alignUp(size_t v) {
  return (v + kBufferAlign - 1) / kBufferAlign * kBufferAlign;
}

// The header's counters, shared with another process: always atomic.
std::atomic_ref<uint64_t> counter(const std::byte* memory, size_t offset) {
  auto* p = const_cast<std::byte*>(memory) + offset;
  return std::atomic_ref<uint64_t>(*reinterpret_cast<uint64_t*>(p));
}
size_t sequenceOffset(uint64_t buffer) {
  return offsetof(ShmHeader, buffer_sequence) + buffer * sizeof(uint64_t);
}
constexpr size_t kFrontOffset = offsetof(ShmHeader, front);
constexpr size_t kFramesOffset = offsetof(ShmHeader, frames);

uint32_t formatCode(PixelFormat f) {
  return f == PixelFormat::kRgb8 ? 0 : 1;
}

class SharedFrames final : public ContentSource {
 public:
  SharedFrames(UniqueFd fd, void* map, size_t bytes, cv::Size size, PixelFormat format)
      : fd_(std::move(fd)),
        map_(map),
        bytes_(bytes),
        size_(size),
        format_(format),
        reader_(static_cast<const std::byte*>(map), size, format) {}
  ~SharedFrames() override { ::munmap(map_, bytes_); }
  cv::Size size() const override { return size_; }
  PixelFormat format() const override { return format_; }
  // Producers do not signal: the daemon looks for a new frame at display rate.
  std::optional<std::chrono::nanoseconds> frameInterval() const override {
    return std::chrono::nanoseconds(16'666'667);
  }
  Result<ReadStatus> read(Frame& out) override {
    const uint64_t published = reader_.published();
    if (published == seen_) return ReadStatus::kNoFrame;
    cv::Mat pixels = spareBuffer();
    if (!reader_.copyNewest(pixels)) return ReadStatus::kNoFrame;  // mid-write: next tick
    seen_ = published;
    out.pixels = std::move(pixels);
    out.format = format_;
    out.sequence = ++sequence_;
    out.timestamp = std::chrono::steady_clock::now().time_since_epoch();
    return ReadStatus::kFrame;
  }

 private:
  // A frame buffer no consumer holds any more (only this pool references it), so
  // that steady streaming does not fault in a fresh 8 MB buffer per frame.
  cv::Mat spareBuffer() {
    for (cv::Mat& m : pool_) {
      if (__atomic_load_n(&m.u->refcount, __ATOMIC_ACQUIRE) == 1) return m;
    }
    const int type = format_ == PixelFormat::kRgb8 ? CV_8UC3 : CV_8UC4;
    cv::Mat fresh(size_, type);
    if (pool_.size() < kPoolSize) pool_.push_back(fresh);
    return fresh;
  }
  static constexpr size_t kPoolSize = 3;

  UniqueFd fd_;
  void* map_;
  size_t bytes_;
  cv::Size size_;
  PixelFormat format_;
  ShmFrameReader reader_;
  std::vector<cv::Mat> pool_;
  uint64_t seen_ = 0;
  uint64_t sequence_ = 0;
};

}  // namespace

size_t shmFrameBytes(cv::Size size, PixelFormat format) {
  return static_cast<size_t>(size.width) * size.height * bytesPerPixel(format);
}

size_t shmTotalBytes(cv::Size size, PixelFormat format) {
  return kShmHeaderBytes + 2 * alignUp(shmFrameBytes(size, format));
}

void initShmHeader(std::span<std::byte> memory, cv::Size size, PixelFormat format) {
  ShmHeader h{};
  h.magic = kShmMagic;
  h.version = kShmVersion;
  h.width = static_cast<uint32_t>(size.width);
  h.height = static_cast<uint32_t>(size.height);
  h.format = formatCode(format);
  h.stride = static_cast<uint32_t>(size.width * bytesPerPixel(format));
  h.buffer_offset[0] = kShmHeaderBytes;
  h.buffer_offset[1] = kShmHeaderBytes + alignUp(shmFrameBytes(size, format));
  std::memcpy(memory.data(), &h, sizeof h);
}

ShmFrameReader::ShmFrameReader(const std::byte* memory, cv::Size size, PixelFormat format)
    : memory_(memory), size_(size), format_(format) {}

uint64_t ShmFrameReader::published() const {
  return counter(memory_, kFramesOffset).load(std::memory_order_acquire);
}

bool ShmFrameReader::copyNewest(cv::Mat& out, int attempts,
                                const std::function<void()>& after_copy) {
  const int type = format_ == PixelFormat::kRgb8 ? CV_8UC3 : CV_8UC4;
  out.create(size_, type);
  const size_t bytes = shmFrameBytes(size_, format_);
  for (int i = 0; i < attempts; ++i) {
    const uint64_t b = counter(memory_, kFrontOffset).load(std::memory_order_acquire) & 1;
    auto seq = counter(memory_, sequenceOffset(b));
    const uint64_t before = seq.load(std::memory_order_acquire);
    if (before & 1) continue;  // being written
    const std::byte* src = memory_ + (b == 0 ? kShmHeaderBytes : kShmHeaderBytes + alignUp(bytes));
    std::memcpy(out.data, src, bytes);
    if (after_copy) after_copy();
    // Seqlock read side: the copy happens before the second sequence read.
    std::atomic_thread_fence(std::memory_order_acquire);
    if (seq.load(std::memory_order_relaxed) == before) return true;
  }
  return false;
}

ShmFrameProducer::ShmFrameProducer(int fd, std::byte* memory, size_t bytes, cv::Size size,
                                   PixelFormat format)
    : fd_(fd), memory_(memory), bytes_(bytes), size_(size), format_(format) {}

ShmFrameProducer::ShmFrameProducer(ShmFrameProducer&& o) noexcept
    : fd_(std::exchange(o.fd_, -1)),
      memory_(std::exchange(o.memory_, nullptr)),
      bytes_(o.bytes_),
      size_(o.size_),
      format_(o.format_),
      writing_(o.writing_) {}

ShmFrameProducer::~ShmFrameProducer() {
  if (memory_) ::munmap(memory_, bytes_);
  if (fd_ >= 0) ::close(fd_);
}

Result<ShmFrameProducer> ShmFrameProducer::create(cv::Size size, PixelFormat format) {
  if (size.width < 2 || size.height < 2 || size.width > kMaxSide || size.height > kMaxSide) {
    return fail(ErrorCode::kInvalidInput, "shared frames must be 2x2 to 16384x16384 pixels");
  }
  UniqueFd fd(::memfd_create("procam-content", MFD_CLOEXEC | MFD_ALLOW_SEALING));
  if (!fd.valid())
    return fail(ErrorCode::kIo, std::string("memfd_create: ") + std::strerror(errno));
  const size_t bytes = shmTotalBytes(size, format);
  if (::ftruncate(fd.get(), static_cast<off_t>(bytes)) != 0) {
    return fail(ErrorCode::kIo, std::string("ftruncate: ") + std::strerror(errno));
  }
  void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd.get(), 0);
  if (map == MAP_FAILED) return fail(ErrorCode::kIo, std::string("mmap: ") + std::strerror(errno));
  auto* memory = static_cast<std::byte*>(map);
  initShmHeader({memory, bytes}, size, format);
  if (::fcntl(fd.get(), F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0) {
    ::munmap(map, bytes);
    return fail(ErrorCode::kIo, std::string("F_ADD_SEALS: ") + std::strerror(errno));
  }
  return ShmFrameProducer(fd.release(), memory, bytes, size, format);
}

uint8_t* ShmFrameProducer::beginWrite() {
  const uint64_t front = counter(memory_, kFrontOffset).load(std::memory_order_relaxed) & 1;
  writing_ = 1 - front;
  auto seq = counter(memory_, sequenceOffset(writing_));
  seq.store(seq.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);  // odd
  // Seqlock write side: the odd sequence is visible before any pixel changes.
  std::atomic_thread_fence(std::memory_order_release);
  const size_t offset =
      writing_ == 0 ? kShmHeaderBytes : kShmHeaderBytes + alignUp(shmFrameBytes(size_, format_));
  return reinterpret_cast<uint8_t*>(memory_ + offset);
}

void ShmFrameProducer::endWrite() {
  auto seq = counter(memory_, sequenceOffset(writing_));
  seq.store(seq.load(std::memory_order_relaxed) + 1, std::memory_order_release);  // even
  counter(memory_, kFrontOffset).store(writing_, std::memory_order_release);
  counter(memory_, kFramesOffset).fetch_add(1, std::memory_order_release);
}

void ShmFrameProducer::publish(const uint8_t* pixels) {
  std::memcpy(beginWrite(), pixels, shmFrameBytes(size_, format_));
  endWrite();
}

Result<std::unique_ptr<ContentSource>> openSharedFrames(int raw_fd, cv::Size size,
                                                        PixelFormat format) {
  UniqueFd fd(raw_fd);
  if (size.width < 2 || size.height < 2 || size.width > kMaxSide || size.height > kMaxSide) {
    return fail(ErrorCode::kInvalidInput, "shared frames must be 2x2 to 16384x16384 pixels");
  }
  const int seals = ::fcntl(fd.get(), F_GET_SEALS);
  if (seals < 0) {
    return fail(ErrorCode::kInvalidInput,
                "the descriptor is not a memfd created with MFD_ALLOW_SEALING");
  }
  if ((seals & kShmRequiredSeals) != kShmRequiredSeals) {
    return fail(ErrorCode::kInvalidInput,
                "the memfd is not sealed: it needs F_SEAL_SHRINK, F_SEAL_GROW and F_SEAL_SEAL");
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) {
    return fail(ErrorCode::kIo, std::string("fstat: ") + std::strerror(errno));
  }
  const size_t need = shmTotalBytes(size, format);
  if (static_cast<size_t>(st.st_size) < need) {
    return fail(ErrorCode::kInvalidInput,
                "the memfd is too small: " + std::to_string(st.st_size) + " bytes, " +
                    std::to_string(size.width) + "x" + std::to_string(size.height) + " " +
                    std::string(toString(format)) + " needs " + std::to_string(need));
  }
  void* map = ::mmap(nullptr, need, PROT_READ, MAP_SHARED, fd.get(), 0);
  if (map == MAP_FAILED) return fail(ErrorCode::kIo, std::string("mmap: ") + std::strerror(errno));
  ShmHeader h;
  std::memcpy(&h, map, sizeof h);
  std::vector<std::byte> expected(sizeof(ShmHeader));
  initShmHeader(expected, size, format);
  ShmHeader want;
  std::memcpy(&want, expected.data(), sizeof want);
  if (h.magic != want.magic || h.version != want.version || h.width != want.width ||
      h.height != want.height || h.format != want.format || h.stride != want.stride ||
      h.buffer_offset[0] != want.buffer_offset[0] || h.buffer_offset[1] != want.buffer_offset[1]) {
    ::munmap(map, need);
    return fail(ErrorCode::kInvalidInput,
                "the memfd header does not describe " + std::to_string(size.width) + "x" +
                    std::to_string(size.height) + " " + std::string(toString(format)) +
                    " frames (magic, version, size, format or offsets differ)");
  }
  return std::unique_ptr<ContentSource>(
      std::make_unique<SharedFrames>(std::move(fd), map, need, size, format));
}

}  // namespace procam::content
