#pragma once
// Stored HID sensor descriptors and reports, and a transport that replays them.
#include <cstdint>
#include <deque>
#include <initializer_list>
#include <optional>
#include <vector>

#include "tilt/hid/hid_accelerometer.hpp"

namespace procam::tilt::testing {

// A sensor-hub style descriptor written from the HID Sensor Usages tables: a sensor
// collection holding an Accelerometer 3D (report 3: X, Y, Z as 16-bit signed with unit
// exponent -2, default unit g, then a constant pad byte) and a Gyrometer 3D (report 4).
// `signed_gyro`: the gyrometer's range -32767..32767 (in degrees per second, the default
// unit, with the same exponent) instead of 0..65535; `gyro_unit`: a Unit item for it.
inline std::vector<std::uint8_t> hubDescriptor(std::uint8_t unit_exponent = 0x0E,
                                               bool si_unit = false, bool signed_gyro = false,
                                               std::optional<std::uint16_t> gyro_unit = {}) {
  std::vector<std::uint8_t> d;
  auto add = [&d](std::initializer_list<std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) d.push_back(b);
  };
  add({
      0x05, 0x20,                             // Usage Page (Sensor)
      0x09, 0x01,                             // Usage (Sensor)
      0xA1, 0x01,                             // Collection (Application)
      0x09, 0x73,                             //   Usage (Motion: Accelerometer 3D)
      0xA1, 0x00,                             //   Collection (Physical)
      0x85, 0x03,                             //     Report ID (3)
      0x17, 0x01,          0x80, 0xFF, 0xFF,  //     Logical Minimum (-32767)
      0x27, 0xFF,          0x7F, 0x00, 0x00,  //     Logical Maximum (32767)
      0x75, 0x10,                             //     Report Size (16)
      0x95, 0x01,                             //     Report Count (1)
      0x55, unit_exponent,                    //     Unit Exponent
  });
  if (si_unit) add({0x66, 0x11, 0xE0});  // Unit (m/s^2, sensor usage tables)
  add({
      0x0A, 0x53, 0x04,  //     Usage (Acceleration Axis X)
      0x81, 0x02,        //     Input (Data, Var, Abs)
      0x0A, 0x54, 0x04,  //     Usage (Acceleration Axis Y)
      0x81, 0x02,        //     Input
      0x0A, 0x55, 0x04,  //     Usage (Acceleration Axis Z)
      0x81, 0x02,        //     Input
      0x75, 0x08,        //     Report Size (8)
      0x81, 0x03,        //     Input (Const): pad
      0xC0,              //   End Collection
      0x09, 0x76,        //   Usage (Motion: Gyrometer 3D)
      0xA1, 0x00,        //   Collection (Physical)
      0x85, 0x04,        //     Report ID (4)
  });
  if (si_unit) add({0x65, 0x00});  // Unit (none): the gyrometer's default
  if (gyro_unit) add({0x66, std::uint8_t(*gyro_unit & 0xFF), std::uint8_t(*gyro_unit >> 8)});
  if (signed_gyro) {
    add({
        0x17, 0x01, 0x80, 0xFF, 0xFF,  //     Logical Minimum (-32767)
        0x27, 0xFF, 0x7F, 0x00, 0x00,  //     Logical Maximum (32767)
    });
  } else {
    add({
        0x15, 0x00,        //     Logical Minimum (0)
        0x26, 0xFF, 0xFF,  //     Logical Maximum (65535, written sign-extended)
    });
  }
  add({
      0x75, 0x10,        //     Report Size (16)
      0x95, 0x03,        //     Report Count (3)
      0x0A, 0x57, 0x04,  //     Usage (Angular Velocity X)
      0x0A, 0x58, 0x04,  //     Usage (Angular Velocity Y)
      0x0A, 0x59, 0x04,  //     Usage (Angular Velocity Z)
      0x81, 0x02,        //     Input
      0xC0,              //   End Collection
      0xC0,              // End Collection
  });
  return d;
}

class ScriptedHid final : public HidTransport {
 public:
  std::vector<std::uint8_t> descriptor;
  std::deque<std::vector<std::uint8_t>> reports;
  Result<std::vector<std::uint8_t>> reportDescriptor() override { return descriptor; }
  Result<std::vector<std::uint8_t>> readReport(int) override {
    if (reports.empty()) return fail(ErrorCode::kNotFound, "timeout");
    auto r = reports.front();
    reports.pop_front();
    return r;
  }
};

inline std::vector<std::uint8_t> accelReport(std::int16_t x, std::int16_t y, std::int16_t z) {
  auto lo = [](std::int16_t v) { return std::uint8_t(std::uint16_t(v) & 0xFF); };
  auto hi = [](std::int16_t v) { return std::uint8_t(std::uint16_t(v) >> 8); };
  return {0x03, lo(x), hi(x), lo(y), hi(y), lo(z), hi(z), 0x00};
}

inline std::vector<std::uint8_t> gyroReport(std::int16_t x, std::int16_t y, std::int16_t z) {
  auto r = accelReport(x, y, z);
  r[0] = 0x04;
  r.pop_back();  // no pad byte
  return r;
}

}  // namespace procam::tilt::testing
