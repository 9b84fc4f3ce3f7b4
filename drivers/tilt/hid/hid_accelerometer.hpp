#pragma once
// HID sensor accelerometers (usage page 0x20, usage 0x73) through hidraw: the report
// descriptor names the X/Y/Z fields, their unit exponent and logical range; input
// reports are decoded with them. The transport is an interface so stored descriptors
// and reports drive the tests.
#include <memory>
#include <string>
#include <vector>

#include "tilt/hid/hid_descriptor.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::tilt {

class HidTransport {
 public:
  virtual ~HidTransport() = default;
  virtual Result<std::vector<std::uint8_t>> reportDescriptor() = 0;
  // One input report (with its report ID byte when the device uses IDs); kNotFound
  // on timeout.
  virtual Result<std::vector<std::uint8_t>> readReport(int timeout_ms) = 0;
  // Readable when a report is waiting; -1 when the transport has no descriptor.
  virtual int pollFd() const { return -1; }
};

// /dev/hidrawN: HIDIOCGRDESCSIZE/HIDIOCGRDESC and read(). Owns the descriptor.
class HidrawTransport final : public HidTransport {
 public:
  static Result<std::unique_ptr<HidrawTransport>> open(const std::string& path);
  ~HidrawTransport() override;
  Result<std::vector<std::uint8_t>> reportDescriptor() override;
  Result<std::vector<std::uint8_t>> readReport(int timeout_ms) override;
  int pollFd() const override { return fd_; }

 private:
  HidrawTransport(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_;
  std::string path_;
};

class HidAccelerometer final : public TiltSensor {
 public:
  explicit HidAccelerometer(std::unique_ptr<HidTransport> transport, int timeout_ms = 200)
      : transport_(std::move(transport)), timeout_ms_(timeout_ms) {}
  ~HidAccelerometer() override { close(); }

  Result<void> open() override;
  // kInvalidInput for a value outside the field's logical range.
  Result<TiltSample> read() override;
  void close() override { open_ = false; }
  std::string name() const override { return "hid"; }
  int pollFd() const override { return transport_->pollFd(); }

  const HidAccelFields& fields() const { return fields_; }

 private:
  std::unique_ptr<HidTransport> transport_;
  int timeout_ms_;
  bool open_ = false;
  bool uses_report_ids_ = false;
  HidAccelFields fields_;
};

}  // namespace procam::tilt
