#include "tracker/hid/wiimote_ir_source.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <numbers>

namespace procam::tracker::wiimote {
namespace {

constexpr std::size_t kMaxReport = 64;  // Wii Remote reports are at most 22 bytes

std::uint64_t monotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::uint64_t(ts.tv_sec) * 1'000'000'000u + std::uint64_t(ts.tv_nsec);
}

std::string hex(std::uint32_t v, int digits) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%0*x", digits, v);
  return text;
}

}  // namespace

Result<std::unique_ptr<HidrawWiimote>> HidrawWiimote::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return fail(ErrorCode::kIo, path + ": " + std::strerror(errno));
  return std::unique_ptr<HidrawWiimote>(new HidrawWiimote(fd, path));
}

HidrawWiimote::~HidrawWiimote() {
  if (fd_ >= 0) ::close(fd_);
}

Result<void> HidrawWiimote::write(std::span<const std::uint8_t> report) {
  const ssize_t n = ::write(fd_, report.data(), report.size());
  if (n < 0) return fail(ErrorCode::kIo, path_ + ": write: " + std::strerror(errno));
  if (std::size_t(n) != report.size())
    return fail(ErrorCode::kIo, path_ + ": short write of an output report");
  return {};
}

Result<std::vector<std::uint8_t>> HidrawWiimote::read(int timeout_ms) {
  pollfd pfd{fd_, POLLIN, 0};
  const int ready = ::poll(&pfd, 1, timeout_ms);
  if (ready < 0) return fail(ErrorCode::kIo, path_ + ": poll: " + std::strerror(errno));
  if (ready == 0) return fail(ErrorCode::kNotFound, path_ + ": no report within the timeout");
  std::vector<std::uint8_t> buf(kMaxReport);
  const ssize_t n = ::read(fd_, buf.data(), buf.size());
  if (n < 0 && (errno == EAGAIN || errno == EINTR))
    return fail(ErrorCode::kNotFound, path_ + ": no report");
  if (n < 0) return fail(ErrorCode::kIo, path_ + ": read: " + std::strerror(errno));
  if (n == 0) return fail(ErrorCode::kIo, path_ + ": the device went away");
  buf.resize(std::size_t(n));
  return buf;
}

geom::CameraModel wiimoteCamera() {
  geom::CameraModel c;
  const double f = (kIrWidth / 2.0) / std::tan(16.5 * std::numbers::pi / 180);
  c.K = {f, f, (kIrWidth - 1) / 2.0, (kIrHeight - 1) / 2.0, 0};
  c.width = kIrWidth;
  c.height = kIrHeight;
  return c;
}

In WiimoteIrSource::dataReport() const {
  return options_.format == IrFormat::kExtended ? In::kButtonsAccelIr12 : In::kButtonsAccelIr10Ext6;
}

Result<WiimoteIrSource> WiimoteIrSource::start(std::unique_ptr<WiimoteTransport> transport,
                                               const WiimoteIrOptions& options, Clock clock) {
  if (!transport) return fail(ErrorCode::kInvalidInput, "wiimote: no transport");
  auto sensitivity = sensitivityLevel(options.sensitivity);
  if (!sensitivity) return tl::unexpected(sensitivity.error());
  if (options.ack_timeout_ms <= 0)
    return fail(ErrorCode::kInvalidInput, "wiimote: the acknowledgement timeout must be > 0 ms");
  if (!clock) clock = &monotonicNow;
  WiimoteIrSource s(std::move(transport), options, std::move(clock));

  const std::uint8_t configuring[] = {0x01}, running[] = {0x08};
  const std::uint8_t mode[] = {static_cast<std::uint8_t>(options.format)};
  struct Write {
    std::uint32_t address;
    std::span<const std::uint8_t> data;
    const char* what;
  };
  const Write writes[] = {
      {kIrControl, configuring, "IR control <- 0x01 (configuring)"},
      {kIrBlock1, sensitivity->block1, "IR sensitivity block 1"},
      {kIrBlock2, sensitivity->block2, "IR sensitivity block 2"},
      {kIrMode, mode, "IR object format"},
      {kIrControl, running, "IR control <- 0x08 (running)"},
  };
  if (auto ok = s.step(setLeds(options.leds, true), "player LEDs"); !ok)
    return tl::unexpected(ok.error());
  if (auto ok = s.step(irPixelClock(true, true), "IR pixel clock on"); !ok)
    return tl::unexpected(ok.error());
  if (auto ok = s.step(irLogic(true, true), "IR logic on"); !ok) return tl::unexpected(ok.error());
  for (const Write& w : writes) {
    auto report = writeRegisters(w.address, w.data);
    if (!report) return tl::unexpected(report.error());
    if (auto ok = s.step(*report, std::string(w.what) + " at " + hex(w.address, 6)); !ok)
      return tl::unexpected(ok.error());
  }
  if (auto ok = s.step(setReportingMode(s.dataReport(), true, true),
                       "data reporting mode " + hex(std::uint8_t(s.dataReport()), 2));
      !ok)
    return tl::unexpected(ok.error());
  return s;
}

// Writes one setup report and waits for its acknowledgement, skipping data reports and
// stale acknowledgements of other reports.
Result<void> WiimoteIrSource::step(const Report& report, const std::string& what) {
  const std::string name = "wiimote: IR setup step '" + what + "', " + describeOut(report[0]);
  if (auto ok = transport_->write(report); !ok)
    return fail(ErrorCode::kIo, name + ": " + ok.error().message);
  using Steady = std::chrono::steady_clock;
  const auto deadline = Steady::now() + std::chrono::milliseconds(options_.ack_timeout_ms);
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Steady::now()).count();
    if (left <= 0) break;
    auto in = transport_->read(int(left));
    if (!in && in.error().code == ErrorCode::kNotFound) break;
    if (!in) return fail(ErrorCode::kIo, name + ": " + in.error().message);
    auto parsed = parseInput(*in);
    if (!parsed) continue;  // a garbled report while waiting is not the answer
    const auto* ack = std::get_if<AckReport>(&*parsed);
    if (!ack || ack->report != report[0]) continue;
    if (ack->error != 0)
      return fail(ErrorCode::kIo, name + ": the Wii Remote answered error " + hex(ack->error, 2));
    return {};
  }
  return fail(ErrorCode::kIo, name + ": no acknowledgement within " +
                                  std::to_string(options_.ack_timeout_ms) + " ms");
}

Result<IrFrame> WiimoteIrSource::read(int timeout_ms) {
  // Reports that are not IR data are consumed without waiting again.
  for (int wait = timeout_ms;; wait = 0) {
    auto in = transport_->read(wait);
    if (!in) return tl::unexpected(in.error());
    auto parsed = parseInput(*in);
    if (!parsed) return tl::unexpected(parsed.error());
    if (std::holds_alternative<StatusReport>(*parsed)) {
      if (auto ok = transport_->write(setReportingMode(dataReport(), true, false)); !ok)
        return tl::unexpected(ok.error());
      continue;
    }
    const auto* ir = std::get_if<IrReport>(&*parsed);
    if (!ir) continue;
    return IrFrame{ir->blobs, ir->buttons, clock_()};
  }
}

}  // namespace procam::tracker::wiimote
