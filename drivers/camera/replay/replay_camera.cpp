#include "camera/replay/replay_camera.hpp"

#include <sys/timerfd.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

namespace procam::camera {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

}  // namespace

Result<std::vector<ReplayEntry>> parseReplayIndex(const std::string& text) {
  std::vector<ReplayEntry> out;
  std::istringstream in(text);
  std::string line;
  double first = 0, last = 0;
  for (int n = 1; std::getline(in, line); ++n) {
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    const std::string where = "index.csv line " + std::to_string(n) + ": ";
    if (comma == std::string::npos)
      return fail(ErrorCode::kInvalidInput, where + "expected 'file,timestamp'");
    const std::string file = trim(line.substr(0, comma));
    const std::string stamp = trim(line.substr(comma + 1));
    if (out.empty() && file == "file" && stamp == "timestamp") continue;  // the header
    char* end = nullptr;
    const double t = std::strtod(stamp.c_str(), &end);
    if (file.empty() || stamp.empty() || *end != '\0' || !std::isfinite(t))
      return fail(ErrorCode::kInvalidInput,
                  where + "'" + stamp + "' is not a timestamp in seconds");
    if (!out.empty() && !(t > last))
      return fail(ErrorCode::kInvalidInput, where + "timestamps must increase");
    if (out.empty()) first = t;
    last = t;
    out.push_back({file, int64_t(std::llround((t - first) * 1e9))});
  }
  if (out.empty()) return fail(ErrorCode::kInvalidInput, "index.csv lists no frames");
  return out;
}

ReplayCamera::ReplayCamera(ReplayOptions options) : options_(std::move(options)) {}

ReplayCamera::~ReplayCamera() {
  stop();
}

Result<void> ReplayCamera::start() {
  stop();
  if (!(options_.speed >= 0) || !std::isfinite(options_.speed))
    return fail(ErrorCode::kInvalidInput, "replay: speed must be >= 0");
  const std::filesystem::path index = std::filesystem::path(options_.dir) / "index.csv";
  std::ifstream in(index);
  if (!in) return fail(ErrorCode::kNoDevice, "replay: cannot read " + index.string());
  std::stringstream text;
  text << in.rdbuf();
  auto entries = parseReplayIndex(text.str());
  if (!entries)
    return fail(entries.error().code, "replay " + options_.dir + ": " + entries.error().message);
  entries_ = std::move(*entries);
  // The first image fixes the format every later one must have.
  Frame first;
  if (auto ok = load(0, first); !ok) return ok;
  format_ = {uint32_t(first.image.cols), uint32_t(first.image.rows), first.pixel};
  timer_fd_ = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (timer_fd_ < 0)
    return fail(ErrorCode::kIo, std::string("replay: timerfd: ") + std::strerror(errno));
  next_ = 0;
  start_ns_ = monotonicNs();
  armTimer();
  return {};
}

void ReplayCamera::stop() {
  if (timer_fd_ >= 0) ::close(timer_fd_);
  timer_fd_ = -1;
}

uint64_t ReplayCamera::dueNs(std::size_t i) const {
  if (options_.speed == 0) return 0;
  return start_ns_ + uint64_t(double(entries_[i].offset_ns) / options_.speed);
}

void ReplayCamera::armTimer() {
  if (timer_fd_ < 0) return;
  // An absolute expiry in the past fires at once, so a due frame is readable; so is the
  // end of the recording, for the reader to learn of it (or to start over).
  const uint64_t due = next_ < entries_.size() ? std::max<uint64_t>(dueNs(next_), 1) : 1;
  itimerspec spec{};
  spec.it_value.tv_sec = time_t(due / 1'000'000'000ull);
  spec.it_value.tv_nsec = long(due % 1'000'000'000ull);
  timerfd_settime(timer_fd_, TFD_TIMER_ABSTIME, &spec, nullptr);
}

Result<void> ReplayCamera::load(std::size_t i, Frame& out) {
  const std::string path = (std::filesystem::path(options_.dir) / entries_[i].file).string();
  decoded_ = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (decoded_.empty()) return fail(ErrorCode::kIo, "replay: cannot read image " + path);
  SourceFormat f;
  if (decoded_.depth() == CV_16U && decoded_.channels() == 1) {
    f = SourceFormat::kY16;
  } else if (decoded_.depth() != CV_8U) {
    return fail(ErrorCode::kInvalidInput, "replay: " + path + " is neither 8- nor 16-bit mono");
  } else if (decoded_.channels() == 1) {
    f = SourceFormat::kGrey;
  } else if (decoded_.channels() == 3) {
    f = SourceFormat::kBgr24;
  } else if (decoded_.channels() == 4) {
    cv::cvtColor(decoded_, decoded_, cv::COLOR_BGRA2BGR);
    f = SourceFormat::kBgr24;
  } else {
    return fail(ErrorCode::kInvalidInput, "replay: " + path + " has an unsupported channel count");
  }
  const procam_pixel_format want =
      options_.pixel.value_or(i == 0 ? naturalPixel(f) : format_.pixel);
  const SourceImage src{f,
                        decoded_.data,
                        decoded_.total() * decoded_.elemSize(),
                        uint32_t(decoded_.cols),
                        uint32_t(decoded_.rows),
                        uint32_t(decoded_.step[0])};
  // The decoded image lives until the next load: wrap it rather than copy it again.
  if (auto ok = convertFrame(src, want, true, storage_, out); !ok)
    return fail(ok.error().code, "replay: " + path + ": " + ok.error().message);
  if (i > 0 &&
      (uint32_t(out.image.cols) != format_.width || uint32_t(out.image.rows) != format_.height))
    return fail(ErrorCode::kInvalidInput,
                "replay: " + path + " is " + std::to_string(out.image.cols) + "x" +
                    std::to_string(out.image.rows) + ", the recording is " +
                    std::to_string(format_.width) + "x" + std::to_string(format_.height));
  // Decoding a file is the one copy a replayed frame costs.
  out.copies = 1 + out.copies;
  out.sequence = i;
  return {};
}

Result<const Frame*> ReplayCamera::capture(int timeout_ms) {
  if (timer_fd_ < 0) return fail(ErrorCode::kInvalidInput, "replay: not started");
  if (next_ >= entries_.size()) {
    if (!options_.loop)
      return fail(ErrorCode::kEnded, "replay " + options_.dir + ": end of the recording (" +
                                         std::to_string(entries_.size()) + " frames)");
    next_ = 0;
    start_ns_ = monotonicNs();
  }
  uint64_t expirations = 0;
  (void)!::read(timer_fd_, &expirations, sizeof expirations);  // clear readability
  const uint64_t due = dueNs(next_);
  const uint64_t now = monotonicNs();
  if (due > now) {
    const uint64_t wait = due - now;
    if (timeout_ms == 0) {
      armTimer();
      return fail(ErrorCode::kAgain, "replay: next frame not due yet");
    }
    if (timeout_ms > 0 && wait > uint64_t(timeout_ms) * 1'000'000ull) {
      std::this_thread::sleep_for(std::chrono::milliseconds(timeout_ms));
      armTimer();
      return fail(ErrorCode::kTimeout,
                  "replay: no frame due within " + std::to_string(timeout_ms) + " ms");
    }
    std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
  }
  if (auto ok = load(next_, frame_); !ok) return tl::unexpected(ok.error());
  frame_.timestamp_ns = start_ns_ + uint64_t(entries_[next_].offset_ns);
  ++next_;
  armTimer();
  return &frame_;
}

Result<void> ReplayCamera::setControl(Control control, double) {
  // The recording fixed exposure, gain and white balance when it was made.
  return unsupported(name(), control);
}

}  // namespace procam::camera
