#pragma once
// Linux IIO accelerometers (kernel ABI Documentation/ABI/testing/sysfs-bus-iio): polled
// through sysfs (in_accel_{x,y,z}_raw with _scale and _offset, per axis or shared:
// value = (raw + offset) * scale in m/s^2; a combined IMU's gyroscope likewise from
// in_anglvel_{x,y,z}_raw, in rad/s, read with every sample), or buffered through the character
// device (scan_elements/, buffer/enable, records read from /dev/iio:deviceN). The device directory
// is configurable, so tests run against a fake tree.
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tilt/iio/iio_scan_type.hpp"
#include "tilt/tilt_sensor.hpp"

namespace procam::tilt {

struct IioConfig {
  std::string device_dir;             // e.g. /sys/bus/iio/devices/iio:device0
  std::string device_node;            // default: /dev/<basename of device_dir>
  bool buffered = true;               // use the buffer when scan_elements/ exists
  std::optional<double> sampling_hz;  // written to sampling_frequency when given
  int buffer_length = 64;
  int poll_timeout_ms = 100;  // wait for a buffered record
};

class IioAccelerometer final : public TiltSensor {
 public:
  explicit IioAccelerometer(IioConfig config) : config_(std::move(config)) {}
  ~IioAccelerometer() override { close(); }

  Result<void> open() override;
  Result<TiltSample> read() override;
  void close() override;
  std::string name() const override { return "iio"; }
  int pollFd() const override { return fd_; }  // the buffer's character device

  bool buffered() const { return fd_ >= 0; }
  std::optional<double> samplingHz() const { return sampling_hz_; }
  bool hasGyroscope() const { return gyro_; }

 private:
  Result<std::string> attribute(const std::string& rel) const;
  Result<void> setAttribute(const std::string& rel, const std::string& value) const;
  bool hasAttribute(const std::string& rel) const;
  Result<void> openBuffer();
  // in_<type>_<axis>_scale or the shared in_<type>_scale, and the offset likewise (0
  // when there is none).
  Result<std::pair<double, double>> scaleAndOffset(const std::string& type, int axis) const;
  // The three in_<type>_<axis>_raw values through scale and offset (polled reading).
  Result<Vec3> polledChannels(const char* type, const std::array<double, 3>& scale,
                              const std::array<double, 3>& offset) const;

  IioConfig config_;
  bool open_ = false;
  std::array<double, 3> scale_{}, offset_{};
  bool gyro_ = false;  // the device has anglvel channels (and the buffer carries them)
  std::array<double, 3> gyro_scale_{}, gyro_offset_{};
  std::optional<double> sampling_hz_;
  int fd_ = -1;
  std::vector<IioScanChannel> channels_;
  std::size_t record_size_ = 0;
};

}  // namespace procam::tilt
