#pragma once
// HID report descriptor parsing (HID 1.11 §6.2.2) for sensor accelerometers and
// gyrometers (HID Sensor Usages: page 0x20, Accelerometer 3D 0x73 with Acceleration Axis
// X/Y/Z 0x453..0x455, Gyrometer 3D 0x76 with Angular Velocity X/Y/Z 0x457..0x459).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"

namespace procam::tilt {

struct HidField {
  std::uint8_t report_id = 0;  // 0 when the device uses no report IDs
  std::uint16_t usage_page = 0;
  std::uint16_t usage = 0;
  std::uint32_t bit_offset = 0;  // within the report, after the report ID byte
  std::uint32_t bit_size = 0;
  std::int64_t logical_min = 0, logical_max = 0;
  std::uint32_t unit = 0;
  int unit_exponent = 0;
  // Usage of the innermost application/physical collection enclosing the field.
  std::uint16_t collection_page = 0, collection_usage = 0;

  bool isSigned() const { return logical_min < 0; }
  // Raw value from a report (without its report ID byte); nullopt if it does not fit.
  std::optional<std::int64_t> extract(std::span<const std::uint8_t> report) const;
};

struct HidDescriptor {
  std::vector<HidField> inputs;
  bool uses_report_ids = false;
};

// kParse for truncated items, unbalanced collections or push/pop misuse.
Result<HidDescriptor> parseHidDescriptor(std::span<const std::uint8_t> bytes);

struct HidAccelFields {
  HidField axis[3];
  double scale = 0;  // m/s^2 per logical unit (unit and unit exponent applied)
};

// The X/Y/Z acceleration input fields of the first Accelerometer 3D collection.
// kNotFound when absent; kInvalidInput for an unsupported unit.
Result<HidAccelFields> findAccelerometer(const HidDescriptor& d);

struct HidGyroFields {
  HidField axis[3];
  double scale = 0;  // rad/s per logical unit (unit and unit exponent applied)
};

// The X/Y/Z angular velocity input fields of the first Gyrometer 3D collection (the
// default unit is degrees per second). kNotFound when absent; kInvalidInput for an
// unsupported unit.
Result<HidGyroFields> findGyrometer(const HidDescriptor& d);

}  // namespace procam::tilt
