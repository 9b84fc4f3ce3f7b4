#include "raw_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "core/unique_fd.hpp"

namespace procam::content {

using procam::UniqueFd;

namespace {

class RawFrames final : public ContentSource {
 public:
  RawFrames(UniqueFd fd, bool fifo, RawFormat format, std::string path)
      : fd_(std::move(fd)), fifo_(fifo), format_(format), path_(std::move(path)) {
    frame_bytes_ = static_cast<size_t>(format_.size.area()) * bytesPerPixel(format_.format);
    buffer_.resize(frame_bytes_);
  }
  cv::Size size() const override { return format_.size; }
  PixelFormat format() const override { return format_.format; }
  int pollFd() const override { return fifo_ ? fd_.get() : -1; }
  std::optional<std::chrono::nanoseconds> frameInterval() const override {
    if (fifo_ || format_.fps <= 0) return std::nullopt;
    return std::chrono::nanoseconds(std::llround(1e9 / format_.fps));
  }

  Result<ReadStatus> read(Frame& out) override {
    if (ended_) return ReadStatus::kEnd;
    while (filled_ < frame_bytes_) {
      const ssize_t n = ::read(fd_.get(), buffer_.data() + filled_, frame_bytes_ - filled_);
      if (n < 0) {
        if (errno == EINTR) continue;
        if (errno == EAGAIN || errno == EWOULDBLOCK) return ReadStatus::kNoFrame;
        ended_ = true;
        return fail(ErrorCode::kIo, path_ + ": " + std::strerror(errno));
      }
      if (n == 0) {
        // A FIFO reads as empty before its first writer opens it: keep waiting.
        if (fifo_ && total_ == 0 && filled_ == 0) return ReadStatus::kNoFrame;
        ended_ = true;
        if (filled_ != 0) {
          return fail(ErrorCode::kIo, path_ + ": partial frame at end of stream (" +
                                          std::to_string(filled_) + " of " +
                                          std::to_string(frame_bytes_) + " bytes)");
        }
        return ReadStatus::kEnd;
      }
      filled_ += static_cast<size_t>(n);
      total_ += static_cast<size_t>(n);
    }
    filled_ = 0;
    const int type = format_.format == PixelFormat::kRgb8 ? CV_8UC3 : CV_8UC4;
    out.pixels = cv::Mat(format_.size, type, buffer_.data()).clone();
    out.format = format_.format;
    out.sequence = ++sequence_;
    if (auto interval = frameInterval()) {
      out.timestamp = *interval * static_cast<int64_t>(sequence_ - 1);
    } else {
      out.timestamp = std::chrono::steady_clock::now().time_since_epoch();
    }
    return ReadStatus::kFrame;
  }

 private:
  UniqueFd fd_;
  bool fifo_;
  RawFormat format_;
  std::string path_;
  size_t frame_bytes_ = 0;
  std::vector<uint8_t> buffer_;
  size_t filled_ = 0;  // bytes of the frame being assembled
  size_t total_ = 0;   // bytes read so far
  uint64_t sequence_ = 0;
  bool ended_ = false;
};

Result<void> checkFormat(const RawFormat& format) {
  if (format.size.width < 2 || format.size.height < 2) {
    return fail(ErrorCode::kInvalidInput, "raw frames must be at least 2x2 pixels");
  }
  if (!(format.fps >= 0) || !std::isfinite(format.fps)) {
    return fail(ErrorCode::kInvalidInput, "fps must be a finite number >= 0");
  }
  return {};
}

}  // namespace

Result<std::unique_ptr<ContentSource>> openRawFrames(const std::string& path,
                                                     const RawFormat& format) {
  if (auto ok = checkFormat(format); !ok) return tl::unexpected(ok.error());
  // Non-blocking so that opening a FIFO does not wait for its writer.
  UniqueFd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (!fd.valid()) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
  return openRawFrames(std::move(fd), path, format);
}

Result<std::unique_ptr<ContentSource>> openRawFrames(UniqueFd fd, const std::string& path,
                                                     const RawFormat& format) {
  if (auto ok = checkFormat(format); !ok) return tl::unexpected(ok.error());
  // A FIFO stays non-blocking (read whenever readable); a regular file reads plainly.
  ::fcntl(fd.get(), F_SETFL, ::fcntl(fd.get(), F_GETFL) | O_NONBLOCK);
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
  const bool fifo = S_ISFIFO(st.st_mode);
  if (!fifo && !S_ISREG(st.st_mode)) {
    return fail(ErrorCode::kIo, path + ": neither a regular file nor a FIFO");
  }
  if (!fifo) {
    // Regular files never block; clear O_NONBLOCK for plain reads.
    ::fcntl(fd.get(), F_SETFL, ::fcntl(fd.get(), F_GETFL) & ~O_NONBLOCK);
  }
  return std::unique_ptr<ContentSource>(
      std::make_unique<RawFrames>(std::move(fd), fifo, format, path));
}

}  // namespace procam::content
