#pragma once
// The Wii Remote's HID report codec for its IR camera (pure, no I/O). Facts from the
// community's reverse engineering (wiibrew.org "Wiimote" protocol and IR camera pages):
// - every output report's first payload byte carries rumble in bit 0; bit 1 asks for an
//   acknowledgement (input report 0x22) on the reports that do not send one anyway;
// - the IR camera starts with its pixel clock (0x13) and logic (0x1a) enabled, then
//   register writes (0x16, address space 0x04): 0xb00030 <- 0x01 (configuring),
//   sensitivity block 1 (9 bytes) at 0xb00000, block 2 (2 bytes) at 0xb0001a, the
//   object format at 0xb00033 (1 basic, 3 extended), 0xb00030 <- 0x08 (running);
// - the camera reports up to 4 objects in 1024x768 sub-pixel units (8x its 128x96
//   sensor); 0x3ff in both coordinates (all ones) marks an empty slot.
// Over hidraw the first byte of every report is its report ID (the kernel adds and
// strips Bluetooth's 0xa1/0xa2 transaction header).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::tracker::wiimote {

inline constexpr std::uint16_t kVendorNintendo = 0x057e;
inline constexpr std::uint16_t kProductWiimote = 0x0306;      // RVL-CNT-01
inline constexpr std::uint16_t kProductWiimotePlus = 0x0330;  // RVL-CNT-01-TR
inline constexpr int kIrWidth = 1024, kIrHeight = 768;
inline constexpr int kMaxBlobs = 4;

using Report = std::vector<std::uint8_t>;

// Output report IDs.
enum class Out : std::uint8_t {
  kLeds = 0x11,
  kReportingMode = 0x12,
  kIrPixelClock = 0x13,
  kStatusRequest = 0x15,
  kWriteMemory = 0x16,
  kIrLogic = 0x1a,
};

// Input report IDs this driver reads.
enum class In : std::uint8_t {
  kStatus = 0x20,
  kAck = 0x22,
  kButtonsAccelIr12 = 0x33,      // extended IR format: 3 bytes per object
  kButtonsIr10Ext9 = 0x36,       // basic IR format: 5 bytes per two objects
  kButtonsAccelIr10Ext6 = 0x37,  // basic IR format
};

// The camera's object format (register 0xb00033) and the data report that carries it.
enum class IrFormat : std::uint8_t { kBasic = 1, kExtended = 3 };

// Sensitivity registers: block 1 at 0xb00000, block 2 at 0xb0001a.
struct IrSensitivity {
  std::array<std::uint8_t, 9> block1;
  std::array<std::uint8_t, 2> block2;
};
// The console's levels 1..5 (its sensor bar sensitivity setting); kInvalidInput outside.
Result<IrSensitivity> sensitivityLevel(int level);

inline constexpr std::uint32_t kIrControl = 0xb00030;  // 0x01 configuring, 0x08 running
inline constexpr std::uint32_t kIrBlock1 = 0xb00000;
inline constexpr std::uint32_t kIrBlock2 = 0xb0001a;
inline constexpr std::uint32_t kIrMode = 0xb00033;

// Output reports. `ack` sets bit 1 (the Wii Remote answers with 0x22).
Report setLeds(std::uint8_t mask, bool ack, bool rumble = false);  // mask bits 0..3: LED 1..4
Report setReportingMode(In mode, bool continuous, bool ack, bool rumble = false);
Report irPixelClock(bool on, bool ack, bool rumble = false);
Report irLogic(bool on, bool ack, bool rumble = false);
Report statusRequest(bool rumble = false);
// 0x16 to the register space: 1..16 bytes at a 24-bit address; kInvalidInput otherwise.
Result<Report> writeRegisters(std::uint32_t address, std::span<const std::uint8_t> data,
                              bool rumble = false);

// Core buttons (two bytes, big-endian, without the bits other reports reuse).
enum Button : std::uint16_t {
  kLeft = 0x0100,
  kRight = 0x0200,
  kDown = 0x0400,
  kUp = 0x0800,
  kPlus = 0x1000,
  kTwo = 0x0001,
  kOne = 0x0002,
  kB = 0x0004,
  kA = 0x0008,
  kMinus = 0x0010,
  kHome = 0x0080,
};
inline constexpr std::uint16_t kButtonMask = 0x1f9f;

struct IrBlob {
  Vec2 pixel = Vec2::Zero();  // camera pixels, 0..1023 x 0..767
  int size = -1;              // 0..15 (extended format), -1 when the format has none
};

struct StatusReport {
  std::uint16_t buttons = 0;
  bool battery_low = false, extension = false, speaker = false, ir = false;
  std::uint8_t leds = 0;  // bits 0..3: LED 1..4
  std::uint8_t battery = 0;
};

struct AckReport {
  std::uint16_t buttons = 0;
  std::uint8_t report = 0;  // the output report acknowledged
  std::uint8_t error = 0;   // 0: success
};

struct IrReport {
  In id = In::kButtonsAccelIr12;
  std::uint16_t buttons = 0;
  std::vector<IrBlob> blobs;  // the occupied slots, in slot order (<= 4)
};

// Any other input report (buttons only, memory reads, extension data): its ID.
struct OtherReport {
  std::uint8_t id = 0;
};

using InputReport = std::variant<StatusReport, AckReport, IrReport, OtherReport>;

// kInvalidInput for an empty report or one shorter than its ID's layout; kParse for an
// IR slot outside the 1024x768 grid that is not the empty marker.
Result<InputReport> parseInput(std::span<const std::uint8_t> report);

// Encoders of the IR data reports, for recorded streams and tests: blobs beyond the
// 4 slots are dropped, pixels are rounded to the 10-bit grid, off-grid ones leave the
// slot empty. 0x33: accelerometer bytes zero (at rest: unused by the tracker).
Report encodeIrExtended(std::uint16_t buttons, std::span<const IrBlob> blobs);
Report encodeIrBasic(In id, std::uint16_t buttons, std::span<const Vec2> blobs);

std::string describeOut(std::uint8_t id);  // "IR pixel clock (0x13)"

}  // namespace procam::tracker::wiimote
