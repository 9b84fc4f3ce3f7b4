#pragma once
// The Wii Remote's IR camera as a source of blob frames: a transport (hidraw, or a
// scripted one in tests) carries the reports of wiimote_reports.hpp; WiimoteIrSource
// runs the camera's setup sequence, waiting for each step's acknowledgement, then
// yields up to 4 blobs per data report with a CLOCK_MONOTONIC timestamp.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "geometry/camera_model.hpp"
#include "tracker/hid/wiimote_reports.hpp"

namespace procam::tracker::wiimote {

class WiimoteTransport {
 public:
  virtual ~WiimoteTransport() = default;
  // One output report, its ID first.
  virtual Result<void> write(std::span<const std::uint8_t> report) = 0;
  // One input report, its ID first; kNotFound when none arrives within the timeout,
  // kIo when the device failed or went away.
  virtual Result<std::vector<std::uint8_t>> read(int timeout_ms) = 0;
  // Readable when a report is waiting; -1 without a descriptor.
  virtual int pollFd() const { return -1; }
};

// /dev/hidrawN opened read-write; owns the descriptor.
class HidrawWiimote final : public WiimoteTransport {
 public:
  static Result<std::unique_ptr<HidrawWiimote>> open(const std::string& path);
  ~HidrawWiimote() override;
  HidrawWiimote(const HidrawWiimote&) = delete;
  HidrawWiimote& operator=(const HidrawWiimote&) = delete;

  Result<void> write(std::span<const std::uint8_t> report) override;
  Result<std::vector<std::uint8_t>> read(int timeout_ms) override;
  int pollFd() const override { return fd_; }

 private:
  HidrawWiimote(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_;
  std::string path_;
};

// The IR camera's pinhole model: 1024x768 over about 33 deg horizontally (wiibrew,
// "Wiimote": IR camera), square pixels: f = 512 / tan(16.5 deg) = 1728.5 px (the vertical
// field is then 25 deg against the quoted 23: the published figures are rounded and
// disagree; calibrate and override fx fy cx cy for accuracy). Principal point at the
// grid's centre (pixel centres at integers, ARCHITECTURE.md). At the origin, pose identity.
geom::CameraModel wiimoteCamera();

struct WiimoteIrOptions {
  IrFormat format = IrFormat::kExtended;  // extended: report 0x33; basic: 0x37
  int sensitivity = 3;                    // sensitivityLevel()
  std::uint8_t leds = 0x1;                // player LEDs lit while tracking (bits 0..3)
  int ack_timeout_ms = 500;               // per setup step
};

struct IrFrame {
  std::vector<IrBlob> blobs;  // <= 4, camera pixels; size is the blob's weight (extended)
  std::uint16_t buttons = 0;
  std::uint64_t timestamp_ns = 0;  // CLOCK_MONOTONIC at reception (or the injected clock)
};

using Clock = std::function<std::uint64_t()>;  // ns

class WiimoteIrSource {
 public:
  // Runs the setup: player LEDs, IR pixel clock (0x13), IR logic (0x1a), the register
  // writes, then the data reporting mode, each acknowledged within ack_timeout_ms.
  // kIo naming the step on a missing or failed acknowledgement or a failed write;
  // kInvalidInput for bad options. `clock` stamps frames (CLOCK_MONOTONIC when empty).
  static Result<WiimoteIrSource> start(std::unique_ptr<WiimoteTransport> transport,
                                       const WiimoteIrOptions& options, Clock clock = {});

  // The next IR data report. kNotFound when none arrives within the timeout (0: only
  // what is waiting). Acknowledgements and other reports are skipped; an unsolicited
  // status report (an extension plugged in or out) stops the Wii Remote's reporting, so
  // the reporting mode is sent again. A short or garbled report fails this read only.
  Result<IrFrame> read(int timeout_ms);
  int pollFd() const { return transport_->pollFd(); }
  const WiimoteIrOptions& options() const { return options_; }

 private:
  WiimoteIrSource(std::unique_ptr<WiimoteTransport> transport, const WiimoteIrOptions& options,
                  Clock clock)
      : transport_(std::move(transport)), options_(options), clock_(std::move(clock)) {}
  Result<void> step(const Report& report, const std::string& what);
  In dataReport() const;

  std::unique_ptr<WiimoteTransport> transport_;
  WiimoteIrOptions options_;
  Clock clock_;
};

}  // namespace procam::tracker::wiimote
