#pragma once
// HID sensor accelerometers (usage page 0x20, usage 0x73) through hidraw: the report
// descriptor names the X/Y/Z fields, their unit exponent and logical range; input
// reports are decoded with them. A sensor hub's gyrometer (usage 0x76) on the same node
// is read too: each accelerometer sample carries its latest angular velocity. The transport is an
// interface so stored descriptors and reports drive the tests.
#include <memory>
#include <optional>
#include <span>
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
  bool hasGyroscope() const { return gyro_.has_value(); }

  // A gyrometer report older than this when an accelerometer sample comes is not
  // given with it (the hub stopped reporting it).
  static constexpr std::uint64_t kGyroFreshNs = 100'000'000;

 private:
  // The gyrometer's reading in `data` (the report without its ID byte) into last_rate_;
  // a bad report clears it.
  void readGyro(std::span<const std::uint8_t> data, std::uint64_t now_ns);

  std::unique_ptr<HidTransport> transport_;
  int timeout_ms_;
  bool open_ = false;
  bool uses_report_ids_ = false;
  HidAccelFields fields_;
  std::optional<HidGyroFields> gyro_;
  std::optional<Vec3> last_rate_;  // rad/s, sensor axes
  std::uint64_t last_rate_ns_ = 0;
};

}  // namespace procam::tilt
