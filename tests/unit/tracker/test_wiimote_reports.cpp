// The Wii Remote's report codec against reports written by hand from the published
// layouts (wiibrew "Wiimote" protocol and IR camera pages).
#include <gtest/gtest.h>

#include <random>

#include "tracker/hid/wiimote_reports.hpp"

namespace procam::tracker::wiimote {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(WiimoteReports, OutputReportsCarryRumbleAckAndEnableBits) {
  EXPECT_EQ(setLeds(0x1, true), (Bytes{0x11, 0x12}));
  EXPECT_EQ(setLeds(0x9, false, true), (Bytes{0x11, 0x91}));
  EXPECT_EQ(setReportingMode(In::kButtonsAccelIr12, true, true), (Bytes{0x12, 0x06, 0x33}));
  EXPECT_EQ(setReportingMode(In::kButtonsAccelIr10Ext6, false, false), (Bytes{0x12, 0x00, 0x37}));
  EXPECT_EQ(irPixelClock(true, true), (Bytes{0x13, 0x06}));
  EXPECT_EQ(irLogic(true, false, true), (Bytes{0x1a, 0x05}));
  EXPECT_EQ(irLogic(false, false), (Bytes{0x1a, 0x00}));
  EXPECT_EQ(statusRequest(), (Bytes{0x15, 0x00}));
}

TEST(WiimoteReports, RegisterWritesAre22BytesWithA24BitAddress) {
  const std::uint8_t block2[] = {0x63, 0x03};
  auto r = writeRegisters(kIrBlock2, block2);
  ASSERT_TRUE(r);
  Bytes expected(22, 0);
  const Bytes head = {0x16, 0x04, 0xb0, 0x00, 0x1a, 0x02, 0x63, 0x03};
  std::copy(head.begin(), head.end(), expected.begin());
  EXPECT_EQ(*r, expected);

  const std::uint8_t one[] = {0x08};
  auto rumble = writeRegisters(kIrControl, one, true);
  ASSERT_TRUE(rumble);
  EXPECT_EQ((*rumble)[1], 0x05);
  EXPECT_EQ((*rumble)[4], 0x30);

  const std::vector<std::uint8_t> seventeen(17, 0);
  EXPECT_EQ(writeRegisters(kIrBlock1, seventeen).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(writeRegisters(kIrBlock1, {}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(writeRegisters(0x1000000, one).error().code, ErrorCode::kInvalidInput);
}

TEST(WiimoteReports, SensitivityLevelsAreTheConsolesFive) {
  auto l3 = sensitivityLevel(3);
  ASSERT_TRUE(l3);
  EXPECT_EQ(l3->block1,
            (std::array<std::uint8_t, 9>{0x02, 0x00, 0x00, 0x71, 0x01, 0x00, 0xaa, 0x00, 0x64}));
  EXPECT_EQ(l3->block2, (std::array<std::uint8_t, 2>{0x63, 0x03}));
  // Block 2's gain limit stays below block 1's gain (byte 8) at every level.
  for (int level = 1; level <= 5; ++level) {
    auto s = sensitivityLevel(level);
    ASSERT_TRUE(s);
    EXPECT_LT(s->block2[0], s->block1[8]);
  }
  EXPECT_EQ(sensitivityLevel(0).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(sensitivityLevel(6).error().code, ErrorCode::kInvalidInput);
}

TEST(WiimoteReports, ExtendedIrReportDecodes10BitCoordinatesAndSize) {
  // Buttons: Left with accelerometer LSBs in bits 5-6 of the first byte, A in the second.
  const Bytes r = {0x33, 0x61, 0x08, 0x80, 0x80, 0x80, 0xff, 0xff, 0xb5,  // x 1023, y 767, size 5
                   0x00, 0x00, 0x00,                                      // x 0, y 0, size 0
                   0xff, 0xff, 0xff,                                      // empty
                   0x2c, 0x01, 0x5a};  // x 0x12c = 300, y 0x101 = 257, size 10
  auto parsed = parseInput(r);
  ASSERT_TRUE(parsed) << parsed.error().message;
  const auto* ir = std::get_if<IrReport>(&*parsed);
  ASSERT_NE(ir, nullptr);
  EXPECT_EQ(ir->buttons, kLeft | kA);
  ASSERT_EQ(ir->blobs.size(), 3u);
  EXPECT_EQ(ir->blobs[0].pixel, Vec2(1023, 767));
  EXPECT_EQ(ir->blobs[0].size, 5);
  EXPECT_EQ(ir->blobs[1].pixel, Vec2(0, 0));
  EXPECT_EQ(ir->blobs[1].size, 0);
  EXPECT_EQ(ir->blobs[2].pixel, Vec2(300, 257));
  EXPECT_EQ(ir->blobs[2].size, 10);
}

TEST(WiimoteReports, BasicIrReportDecodesPairsOfObjects) {
  // 0x37: buttons, 3 accelerometer bytes, 10 IR bytes, 6 extension bytes.
  Bytes r(22, 0);
  r[0] = 0x37;
  r[2] = 0x80;  // Home
  // (100, 200) and (1000, 700): high bits y1 0, x1 0, y2 2, x2 3.
  const Bytes ir = {0x64, 0xc8, 0x0b, 0xe8, 0xbc, 0xff, 0xff, 0xff, 0xff, 0xff};
  std::copy(ir.begin(), ir.end(), r.begin() + 6);
  auto parsed = parseInput(r);
  ASSERT_TRUE(parsed) << parsed.error().message;
  const auto* report = std::get_if<IrReport>(&*parsed);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->buttons, kHome);
  ASSERT_EQ(report->blobs.size(), 2u);
  EXPECT_EQ(report->blobs[0].pixel, Vec2(100, 200));
  EXPECT_EQ(report->blobs[1].pixel, Vec2(1000, 700));
  EXPECT_EQ(report->blobs[0].size, -1);

  // 0x36 carries the same 10 bytes right after the buttons.
  Bytes r36(22, 0xff);
  r36[0] = 0x36;
  r36[1] = r36[2] = 0;
  std::copy(ir.begin(), ir.begin() + 5, r36.begin() + 3);
  auto p36 = parseInput(r36);
  ASSERT_TRUE(p36);
  ASSERT_EQ(std::get<IrReport>(*p36).blobs.size(), 2u);
  EXPECT_EQ(std::get<IrReport>(*p36).blobs[1].pixel, Vec2(1000, 700));
}

TEST(WiimoteReports, EncodersRoundToTheGridAndRoundTrip) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-0.49, 1023.49), uy(-0.49, 767.49);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<IrBlob> blobs;
    std::vector<Vec2> pixels;
    const int n = trial % 5;  // 0..4 objects
    for (int i = 0; i < n; ++i) {
      pixels.push_back(Vec2(ux(rng), uy(rng)));
      blobs.push_back({pixels.back(), (trial + i) % 16});
    }
    for (const Report& r :
         {encodeIrExtended(kB, blobs), encodeIrBasic(In::kButtonsAccelIr10Ext6, kB, pixels)}) {
      auto parsed = parseInput(r);
      ASSERT_TRUE(parsed) << parsed.error().message;
      const IrReport& ir = std::get<IrReport>(*parsed);
      EXPECT_EQ(ir.buttons, kB);
      ASSERT_EQ(ir.blobs.size(), std::size_t(n));
      for (int i = 0; i < n; ++i) {
        EXPECT_LE((ir.blobs[i].pixel - pixels[i]).cwiseAbs().maxCoeff(), 0.5);
        EXPECT_EQ(ir.blobs[i].pixel, pixels[i].array().round().matrix());
      }
    }
  }
  // Off the grid: the slot stays empty.
  const IrBlob off[] = {{Vec2(1024, 10), 3}, {Vec2(10, -1), 3}, {Vec2(5, 6), 3}};
  auto parsed = parseInput(encodeIrExtended(0, off));
  ASSERT_TRUE(parsed);
  ASSERT_EQ(std::get<IrReport>(*parsed).blobs.size(), 1u);
  EXPECT_EQ(std::get<IrReport>(*parsed).blobs[0].pixel, Vec2(5, 6));
}

TEST(WiimoteReports, StatusAndAcknowledgement) {
  auto status = parseInput(Bytes{0x20, 0x00, 0x02, 0x1a, 0x00, 0x00, 0xc8});
  ASSERT_TRUE(status);
  const auto& s = std::get<StatusReport>(*status);
  EXPECT_EQ(s.buttons, kOne);
  EXPECT_FALSE(s.battery_low);
  EXPECT_TRUE(s.extension);
  EXPECT_TRUE(s.ir);
  EXPECT_EQ(s.leds, 0x1);
  EXPECT_EQ(s.battery, 0xc8);

  auto ack = parseInput(Bytes{0x22, 0x00, 0x00, 0x16, 0x03});
  ASSERT_TRUE(ack);
  EXPECT_EQ(std::get<AckReport>(*ack).report, 0x16);
  EXPECT_EQ(std::get<AckReport>(*ack).error, 0x03);
}

TEST(WiimoteReports, ShortAndGarbledReportsAreTypedErrors) {
  EXPECT_EQ(parseInput(Bytes{}).error().code, ErrorCode::kInvalidInput);
  auto short33 = parseInput(Bytes{0x33, 0x00, 0x00, 0x80, 0x80, 0x80, 0x10, 0x20});
  ASSERT_FALSE(short33);
  EXPECT_EQ(short33.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(short33.error().message.find("0x33 has 8 bytes, needs 18"), std::string::npos)
      << short33.error().message;
  EXPECT_EQ(parseInput(Bytes{0x22, 0x00, 0x00, 0x16}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(parseInput(Bytes{0x20, 0x00}).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(parseInput(Bytes{0x37, 0x00}).error().code, ErrorCode::kInvalidInput);

  // y = 0x320 = 800: past the 768 rows and not the empty marker.
  Bytes garbled = {0x33, 0, 0, 0x80, 0x80, 0x80, 0x10, 0x20, 0xc0};
  garbled.resize(18, 0xff);
  auto bad = parseInput(garbled);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kParse);
  EXPECT_NE(bad.error().message.find("y = 800"), std::string::npos) << bad.error().message;

  // Reports outside the codec's set are named, not decoded.
  auto other = parseInput(Bytes{0x30, 0x00, 0x00});
  ASSERT_TRUE(other);
  EXPECT_EQ(std::get<OtherReport>(*other).id, 0x30);
}

}  // namespace
}  // namespace procam::tracker::wiimote
