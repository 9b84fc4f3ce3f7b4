// WiimoteIrSource on a fake Wii Remote: the IR setup handshake, its failures (named by
// step), and reading frames among other reports.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <numbers>

#include "unit/tracker/fake_wiimote.hpp"

namespace procam::tracker::wiimote {
namespace {

using testing::FakeWiimote;
using Bytes = std::vector<std::uint8_t>;

struct Started {
  std::shared_ptr<std::vector<Report>> written;  // outlives the fake
  Result<WiimoteIrSource> source;
};

// The source's clock reads the fake's time of the last delivered report.
Started start(std::unique_ptr<FakeWiimote> fake, WiimoteIrOptions options = {}) {
  auto written = fake->written;
  FakeWiimote* raw = fake.get();
  auto source = WiimoteIrSource::start(std::move(fake), options, [raw] { return raw->now_ns; });
  return {written, std::move(source)};
}

// (report ID, register address or 0, first data byte or the report's flags byte)
std::vector<std::tuple<int, std::uint32_t, int>> summary(const std::vector<Report>& written) {
  std::vector<std::tuple<int, std::uint32_t, int>> out;
  for (const Report& r : written) {
    if (r[0] == 0x16)
      out.emplace_back(r[0], std::uint32_t(r[2] << 16 | r[3] << 8 | r[4]), r[6]);
    else
      out.emplace_back(r[0], 0, r.back());
  }
  return out;
}

TEST(WiimoteIrSource, SetupFollowsTheCameraSequenceThenReadsFrames) {
  auto fake = std::make_unique<FakeWiimote>();
  const IrBlob blobs[] = {{Vec2(100, 200), 3}, {Vec2(400.4, 300.6), 7}};
  fake->inbox.push_back({encodeIrExtended(kA, blobs), 5'000'000});
  auto [written, source] = start(std::move(fake));
  ASSERT_TRUE(source) << source.error().message;

  using T = std::tuple<int, std::uint32_t, int>;
  const std::vector<T> expected = {
      T{0x11, 0, 0x12},         // LED 1, acknowledge
      T{0x13, 0, 0x06},         // pixel clock on, acknowledge
      T{0x1a, 0, 0x06},         // logic on, acknowledge
      T{0x16, 0xb00030, 0x01},  // configuring
      T{0x16, 0xb00000, 0x02},  // sensitivity block 1 (level 3)
      T{0x16, 0xb0001a, 0x63},  // sensitivity block 2
      T{0x16, 0xb00033, 0x03},  // extended format
      T{0x16, 0xb00030, 0x08},  // running
      T{0x12, 0, 0x33},         // continuous 0x33 reports
  };
  EXPECT_EQ(summary(*written), expected);
  EXPECT_EQ(written->back(), (Bytes{0x12, 0x06, 0x33}));
  EXPECT_EQ((*written)[4][5], 9);  // block 1 is 9 bytes
  EXPECT_EQ((*written)[5][5], 2);

  auto frame = source->read(0);
  ASSERT_TRUE(frame) << frame.error().message;
  ASSERT_EQ(frame->blobs.size(), 2u);
  EXPECT_EQ(frame->blobs[1].pixel, Vec2(400, 301));
  EXPECT_EQ(frame->blobs[1].size, 7);
  EXPECT_EQ(frame->buttons, kA);
  EXPECT_EQ(frame->timestamp_ns, 5'000'000u);
  EXPECT_EQ(source->read(0).error().code, ErrorCode::kNotFound);
}

TEST(WiimoteIrSource, BasicFormatUsesMode1AndReport0x37) {
  WiimoteIrOptions options;
  options.format = IrFormat::kBasic;
  options.sensitivity = 5;
  auto [written, source] = start(std::make_unique<FakeWiimote>(), options);
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ(std::get<2>(summary(*written)[4]), 0x07);  // level 5's first byte
  EXPECT_EQ(std::get<2>(summary(*written)[6]), 0x01);  // 0xb00033 <- basic
  EXPECT_EQ(written->back(), (Bytes{0x12, 0x06, 0x37}));
}

TEST(WiimoteIrSource, MissingAcknowledgementNamesTheStep) {
  auto fake = std::make_unique<FakeWiimote>();
  fake->silent = 0x1a;
  WiimoteIrOptions options;
  options.ack_timeout_ms = 20;
  auto [written, source] = start(std::move(fake), options);
  ASSERT_FALSE(source);
  EXPECT_EQ(source.error().code, ErrorCode::kIo);
  EXPECT_EQ(source.error().message,
            "wiimote: IR setup step 'IR logic on', IR logic (0x1a): no acknowledgement within "
            "20 ms");
  EXPECT_EQ(written->size(), 3u);  // nothing after the failed step
}

TEST(WiimoteIrSource, ErrorAcknowledgementNamesTheStepAndCode) {
  auto fake = std::make_unique<FakeWiimote>();
  fake->error_ack = {{0x16, 0x03}};
  auto [written, source] = start(std::move(fake));
  ASSERT_FALSE(source);
  EXPECT_EQ(source.error().message,
            "wiimote: IR setup step 'IR control <- 0x01 (configuring) at 0xb00030', register "
            "write (0x16): the Wii Remote answered error 0x03");
  EXPECT_EQ(written->size(), 4u);
}

TEST(WiimoteIrSource, FailedWriteNamesTheStep) {
  auto fake = std::make_unique<FakeWiimote>();
  fake->write_fails = true;
  auto [written, source] = start(std::move(fake));
  ASSERT_FALSE(source);
  EXPECT_EQ(source.error().code, ErrorCode::kIo);
  EXPECT_EQ(source.error().message,
            "wiimote: IR setup step 'player LEDs', player LEDs (0x11): write: No such device");
}

TEST(WiimoteIrSource, ReportsBeforeAnAcknowledgementAreSkipped) {
  auto fake = std::make_unique<FakeWiimote>();
  // A data report and a stale acknowledgement of another report ahead of every answer.
  fake->before_ack = Bytes{0x22, 0x00, 0x00, 0x15, 0x00};
  auto [written, source] = start(std::move(fake));
  EXPECT_TRUE(source) << source.error().message;
  auto noisy = std::make_unique<FakeWiimote>();
  const IrBlob one[] = {{Vec2(1, 2), 1}};
  noisy->before_ack = encodeIrExtended(0, one);
  auto [written2, source2] = start(std::move(noisy));
  EXPECT_TRUE(source2) << source2.error().message;
}

TEST(WiimoteIrSource, UnsolicitedStatusResendsTheReportingMode) {
  auto fake = std::make_unique<FakeWiimote>();
  const IrBlob one[] = {{Vec2(10, 20), 2}};
  fake->inbox.push_back({Bytes{0x20, 0x00, 0x00, 0x1a, 0x00, 0x00, 0xc8}, 1});
  fake->inbox.push_back({Bytes{0x30, 0x00, 0x00}, 2});  // buttons only: skipped
  fake->inbox.push_back({encodeIrExtended(0, one), 3});
  auto [written, source] = start(std::move(fake));
  ASSERT_TRUE(source) << source.error().message;
  const std::size_t setup = written->size();
  auto frame = source->read(0);
  ASSERT_TRUE(frame) << frame.error().message;
  EXPECT_EQ(frame->blobs.size(), 1u);
  EXPECT_EQ(frame->timestamp_ns, 3u);
  ASSERT_EQ(written->size(), setup + 1);
  EXPECT_EQ(written->back(), (Bytes{0x12, 0x04, 0x33}));
}

TEST(WiimoteIrSource, GarbledReportFailsOneReadOnly) {
  auto fake = std::make_unique<FakeWiimote>();
  const IrBlob one[] = {{Vec2(10, 20), 2}};
  fake->inbox.push_back({Bytes{0x33, 0x00}, 1});
  fake->inbox.push_back({Bytes{}, 2});
  fake->inbox.push_back({encodeIrExtended(0, one), 3});
  auto [written, source] = start(std::move(fake));
  ASSERT_TRUE(source) << source.error().message;
  auto first = source->read(0);
  ASSERT_FALSE(first);
  EXPECT_EQ(first.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(first.error().message.find("0x33 has 2 bytes"), std::string::npos);
  EXPECT_EQ(source->read(0).error().code, ErrorCode::kInvalidInput);
  auto third = source->read(0);
  ASSERT_TRUE(third) << third.error().message;
  EXPECT_EQ(third->blobs[0].pixel, Vec2(10, 20));
}

TEST(WiimoteIrSource, BadOptionsAreRefused) {
  WiimoteIrOptions options;
  options.sensitivity = 9;
  EXPECT_EQ(start(std::make_unique<FakeWiimote>(), options).source.error().code,
            ErrorCode::kInvalidInput);
  options = {};
  options.ack_timeout_ms = 0;
  EXPECT_EQ(start(std::make_unique<FakeWiimote>(), options).source.error().code,
            ErrorCode::kInvalidInput);
}

// The hidraw transport's fd handling on a FIFO (no hidraw node on this machine): what is
// written comes back as one report, poll times out on an empty one.
TEST(HidrawWiimote, WritesAndReadsWholeReportsOnItsDescriptor) {
  const std::string path = ::testing::TempDir() + "wiimote-fifo-" + std::to_string(::getpid());
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  {
    auto t = HidrawWiimote::open(path);
    ASSERT_TRUE(t) << t.error().message;
    EXPECT_GE((*t)->pollFd(), 0);
    EXPECT_EQ((*t)->read(10).error().code, ErrorCode::kNotFound);
    const Bytes ack = {0x22, 0x00, 0x00, 0x16, 0x00};
    ASSERT_TRUE((*t)->write(ack));
    auto back = (*t)->read(100);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(*back, ack);
  }
  ::unlink(path.c_str());
  auto missing = HidrawWiimote::open(path);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
  EXPECT_NE(missing.error().message.find(path), std::string::npos);
}

TEST(WiimoteCamera, ThirtyThreeDegreesOver1024Pixels) {
  const geom::CameraModel cam = wiimoteCamera();
  EXPECT_EQ(cam.width, 1024);
  EXPECT_EQ(cam.height, 768);
  EXPECT_NEAR(2 * std::atan(512 / cam.K.fx) * 180 / std::numbers::pi, 33.0, 1e-9);
  EXPECT_EQ(cam.K.fx, cam.K.fy);
  EXPECT_EQ(cam.K.cx, 511.5);
  EXPECT_EQ(cam.K.cy, 383.5);
}

}  // namespace
}  // namespace procam::tracker::wiimote
