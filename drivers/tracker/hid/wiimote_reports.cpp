#include "tracker/hid/wiimote_reports.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace procam::tracker::wiimote {
namespace {

constexpr std::uint8_t kRumble = 0x01;
constexpr std::uint8_t kAck = 0x02;
constexpr std::uint8_t kEnable = 0x04;         // 0x13/0x1a: on; 0x12: continuous reporting
constexpr std::uint8_t kRegisterSpace = 0x04;  // 0x16: control registers, not EEPROM
constexpr int kEmpty = 0x3ff;

std::uint8_t flags(bool ack, bool rumble) {
  return std::uint8_t((ack ? kAck : 0) | (rumble ? kRumble : 0));
}

std::uint8_t id(Out o) {
  return static_cast<std::uint8_t>(o);
}

std::uint16_t buttonsAt(std::span<const std::uint8_t> r) {
  return std::uint16_t(((r[1] << 8) | r[2]) & kButtonMask);
}

// Bytes a report needs, ID included; 0 for reports this codec does not decode.
std::size_t lengthOf(std::uint8_t report) {
  switch (static_cast<In>(report)) {
    case In::kStatus:
      return 7;
    case In::kAck:
      return 5;
    case In::kButtonsAccelIr12:
      return 18;
    case In::kButtonsIr10Ext9:
    case In::kButtonsAccelIr10Ext6:
      return 22;
  }
  return 0;
}

// One slot's coordinates; false for the empty marker.
Result<bool> slot(int x, int y, IrBlob& out) {
  if (y == kEmpty) return false;
  if (y >= kIrHeight)
    return fail(ErrorCode::kParse, "wiimote: IR object at y = " + std::to_string(y) +
                                       " outside the 768 rows and not the empty marker");
  out.pixel = Vec2(x, y);
  return true;
}

Result<void> parseExtended(std::span<const std::uint8_t> ir, IrReport& out) {
  for (int i = 0; i < kMaxBlobs; ++i) {
    const std::uint8_t* b = &ir[std::size_t(3 * i)];
    IrBlob blob;
    const int x = b[0] | ((b[2] >> 4) & 0x3) << 8;
    const int y = b[1] | ((b[2] >> 6) & 0x3) << 8;
    auto seen = slot(x, y, blob);
    if (!seen) return tl::unexpected(seen.error());
    blob.size = b[2] & 0x0f;
    if (*seen) out.blobs.push_back(blob);
  }
  return {};
}

Result<void> parseBasic(std::span<const std::uint8_t> ir, IrReport& out) {
  for (int pair = 0; pair < 2; ++pair) {
    const std::uint8_t* b = &ir[std::size_t(5 * pair)];
    const int x[2] = {b[0] | ((b[2] >> 4) & 0x3) << 8, b[3] | (b[2] & 0x3) << 8};
    const int y[2] = {b[1] | ((b[2] >> 6) & 0x3) << 8, b[4] | ((b[2] >> 2) & 0x3) << 8};
    for (int k = 0; k < 2; ++k) {
      IrBlob blob;
      auto seen = slot(x[k], y[k], blob);
      if (!seen) return tl::unexpected(seen.error());
      if (*seen) out.blobs.push_back(blob);
    }
  }
  return {};
}

// A pixel rounded to the 10-bit grid; kEmpty coordinates when off the grid.
std::pair<int, int> quantise(const Vec2& p) {
  const double x = std::round(p.x()), y = std::round(p.y());
  if (!(x >= 0 && x < kIrWidth && y >= 0 && y < kIrHeight)) return {kEmpty, kEmpty};
  return {int(x), int(y)};
}

}  // namespace

Result<IrSensitivity> sensitivityLevel(int level) {
  // The console's five settings (wiibrew, IR camera: sensitivity settings).
  static constexpr IrSensitivity kLevels[5] = {
      {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0x64, 0x00, 0xfe}, {0xfd, 0x05}},
      {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0x96, 0x00, 0xb4}, {0xb3, 0x04}},
      {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0xaa, 0x00, 0x64}, {0x63, 0x03}},
      {{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0xc8, 0x00, 0x36}, {0x35, 0x03}},
      {{0x07, 0x00, 0x00, 0x71, 0x01, 0x00, 0x72, 0x00, 0x20}, {0x1f, 0x03}},
  };
  if (level < 1 || level > 5)
    return fail(ErrorCode::kInvalidInput,
                "wiimote: IR sensitivity level " + std::to_string(level) + " is not 1..5");
  return kLevels[level - 1];
}

Report setLeds(std::uint8_t mask, bool ack, bool rumble) {
  return {id(Out::kLeds), std::uint8_t(((mask & 0x0f) << 4) | flags(ack, rumble))};
}

Report setReportingMode(In mode, bool continuous, bool ack, bool rumble) {
  return {id(Out::kReportingMode), std::uint8_t((continuous ? kEnable : 0) | flags(ack, rumble)),
          static_cast<std::uint8_t>(mode)};
}

Report irPixelClock(bool on, bool ack, bool rumble) {
  return {id(Out::kIrPixelClock), std::uint8_t((on ? kEnable : 0) | flags(ack, rumble))};
}

Report irLogic(bool on, bool ack, bool rumble) {
  return {id(Out::kIrLogic), std::uint8_t((on ? kEnable : 0) | flags(ack, rumble))};
}

Report statusRequest(bool rumble) {
  return {id(Out::kStatusRequest), flags(false, rumble)};
}

Result<Report> writeRegisters(std::uint32_t address, std::span<const std::uint8_t> data,
                              bool rumble) {
  if (data.empty() || data.size() > 16)
    return fail(ErrorCode::kInvalidInput, "wiimote: a register write carries 1..16 bytes, not " +
                                              std::to_string(data.size()));
  if (address > 0xffffff)
    return fail(ErrorCode::kInvalidInput, "wiimote: register addresses have 24 bits");
  Report r(22, 0);
  r[0] = id(Out::kWriteMemory);
  r[1] = std::uint8_t(kRegisterSpace | (rumble ? kRumble : 0));
  r[2] = std::uint8_t(address >> 16);
  r[3] = std::uint8_t(address >> 8);
  r[4] = std::uint8_t(address);
  r[5] = std::uint8_t(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) r[6 + i] = data[i];
  return r;
}

Result<InputReport> parseInput(std::span<const std::uint8_t> r) {
  if (r.empty()) return fail(ErrorCode::kInvalidInput, "wiimote: empty input report");
  const std::size_t need = lengthOf(r[0]);
  if (need == 0) return OtherReport{r[0]};
  if (r.size() < need) {
    char what[96];
    std::snprintf(what, sizeof what, "wiimote: input report 0x%02x has %zu bytes, needs %zu", r[0],
                  r.size(), need);
    return fail(ErrorCode::kInvalidInput, what);
  }
  switch (static_cast<In>(r[0])) {
    case In::kStatus: {
      StatusReport s;
      s.buttons = buttonsAt(r);
      s.battery_low = r[3] & 0x01;
      s.extension = r[3] & 0x02;
      s.speaker = r[3] & 0x04;
      s.ir = r[3] & 0x08;
      s.leds = std::uint8_t(r[3] >> 4);
      s.battery = r[6];
      return s;
    }
    case In::kAck:
      return AckReport{buttonsAt(r), r[3], r[4]};
    case In::kButtonsAccelIr12: {
      IrReport ir{In::kButtonsAccelIr12, buttonsAt(r), {}};
      if (auto ok = parseExtended(r.subspan(6, 12), ir); !ok) return tl::unexpected(ok.error());
      return ir;
    }
    case In::kButtonsIr10Ext9:
    case In::kButtonsAccelIr10Ext6: {
      const In which = static_cast<In>(r[0]);
      IrReport ir{which, buttonsAt(r), {}};
      const std::size_t at = which == In::kButtonsIr10Ext9 ? 3 : 6;
      if (auto ok = parseBasic(r.subspan(at, 10), ir); !ok) return tl::unexpected(ok.error());
      return ir;
    }
  }
  return OtherReport{r[0]};
}

Report encodeIrExtended(std::uint16_t buttons, std::span<const IrBlob> blobs) {
  Report r(18, 0);
  r[0] = static_cast<std::uint8_t>(In::kButtonsAccelIr12);
  r[1] = std::uint8_t((buttons & kButtonMask) >> 8);
  r[2] = std::uint8_t(buttons & kButtonMask);
  for (int i = 0; i < kMaxBlobs; ++i) {
    std::uint8_t* b = &r[std::size_t(6 + 3 * i)];
    const bool present = i < int(blobs.size());
    const auto [x, y] = present ? quantise(blobs[std::size_t(i)].pixel) : std::pair{kEmpty, kEmpty};
    const int size = present && x != kEmpty ? std::clamp(blobs[std::size_t(i)].size, 0, 15) : 0xf;
    b[0] = std::uint8_t(x & 0xff);
    b[1] = std::uint8_t(y & 0xff);
    b[2] = std::uint8_t(((y >> 8) & 0x3) << 6 | ((x >> 8) & 0x3) << 4 | size);
  }
  return r;
}

Report encodeIrBasic(In id, std::uint16_t buttons, std::span<const Vec2> blobs) {
  Report r(22, 0);
  r[0] = static_cast<std::uint8_t>(id);
  r[1] = std::uint8_t((buttons & kButtonMask) >> 8);
  r[2] = std::uint8_t(buttons & kButtonMask);
  const std::size_t at = id == In::kButtonsIr10Ext9 ? 3 : 6;
  for (int pair = 0; pair < 2; ++pair) {
    std::uint8_t* b = &r[at + std::size_t(5 * pair)];
    std::pair<int, int> p[2];
    for (int k = 0; k < 2; ++k) {
      const std::size_t i = std::size_t(2 * pair + k);
      p[k] = i < blobs.size() ? quantise(blobs[i]) : std::pair{kEmpty, kEmpty};
    }
    b[0] = std::uint8_t(p[0].first & 0xff);
    b[1] = std::uint8_t(p[0].second & 0xff);
    b[2] = std::uint8_t(((p[0].second >> 8) & 0x3) << 6 | ((p[0].first >> 8) & 0x3) << 4 |
                        ((p[1].second >> 8) & 0x3) << 2 | ((p[1].first >> 8) & 0x3));
    b[3] = std::uint8_t(p[1].first & 0xff);
    b[4] = std::uint8_t(p[1].second & 0xff);
  }
  return r;
}

std::string describeOut(std::uint8_t report) {
  static constexpr std::pair<Out, const char*> kNames[] = {
      {Out::kLeds, "player LEDs"},
      {Out::kReportingMode, "data reporting mode"},
      {Out::kIrPixelClock, "IR pixel clock"},
      {Out::kStatusRequest, "status request"},
      {Out::kWriteMemory, "register write"},
      {Out::kIrLogic, "IR logic"}};
  const char* name = "output report";
  for (const auto& [out, label] : kNames)
    if (static_cast<std::uint8_t>(out) == report) name = label;
  char text[64];
  std::snprintf(text, sizeof text, "%s (0x%02x)", name, report);
  return text;
}

}  // namespace procam::tracker::wiimote
