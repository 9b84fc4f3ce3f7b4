// Still images and raw frames from a file or a FIFO: exact pixels, end of
// stream, partial frames, a FIFO writer closing.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "content/raw_source.hpp"
#include "content/still_sources.hpp"

namespace procam::content {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/procam-content-XXXXXX";
    path_ = ::mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// Pixel (x, y) channel c of frame k: distinct everywhere, so any shift shows.
uint8_t value(int k, int x, int y, int c) {
  return static_cast<uint8_t>(k * 37 + x * 5 + y * 11 + c * 3);
}
std::vector<uint8_t> frameBytes(int k, cv::Size size, int channels) {
  std::vector<uint8_t> bytes;
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      for (int c = 0; c < channels; ++c) bytes.push_back(value(k, x, y, c));
    }
  }
  return bytes;
}
void expectFrame(const Frame& f, int k, cv::Size size, int channels) {
  ASSERT_EQ(f.pixels.size(), size);
  ASSERT_EQ(f.pixels.channels(), channels);
  const auto want = frameBytes(k, size, channels);
  ASSERT_TRUE(f.pixels.isContinuous());
  EXPECT_EQ(0, std::memcmp(f.pixels.data, want.data(), want.size())) << "frame " << k;
}

TEST(StillImage, PngDecodesToExactRgba) {
  TempDir dir;
  // BGR on disk (OpenCV's order): the frame must come out R first.
  cv::Mat bgr(3, 4, CV_8UC3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) bgr.at<cv::Vec3b>(y, x) = {uint8_t(x), uint8_t(y), uint8_t(200)};
  }
  ASSERT_TRUE(cv::imwrite(dir.file("a.png"), bgr));
  auto source = openStillImage(dir.file("a.png"));
  ASSERT_TRUE(source) << source.error().message;
  Frame f;
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  ASSERT_EQ(f.pixels.type(), CV_8UC4);
  EXPECT_EQ(f.pixels.at<cv::Vec4b>(2, 3), cv::Vec4b(200, 2, 3, 255));
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kEnd);
  auto missing = openStillImage(dir.file("none.png"));
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
}

TEST(RawFrames, FileYieldsWholeFramesThenEnds) {
  TempDir dir;
  const cv::Size size(5, 3);
  {
    std::ofstream out(dir.file("f.raw"), std::ios::binary);
    for (int k = 0; k < 3; ++k) {
      const auto b = frameBytes(k, size, 3);
      out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
    }
  }
  auto source = openRawFrames(dir.file("f.raw"), {size, PixelFormat::kRgb8, 25});
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->pollFd(), -1);
  EXPECT_EQ((*source)->frameInterval(), std::chrono::nanoseconds(40'000'000));
  Frame f;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
    expectFrame(f, k, size, 3);
    EXPECT_EQ(f.sequence, uint64_t(k + 1));
    EXPECT_EQ(f.timestamp, std::chrono::nanoseconds(40'000'000) * k);
  }
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kEnd);
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kEnd);
}

TEST(RawFrames, PartialFrameAtEndIsAnError) {
  TempDir dir;
  const cv::Size size(4, 4);
  {
    std::ofstream out(dir.file("f.raw"), std::ios::binary);
    const auto b = frameBytes(0, size, 4);
    out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
    out.write(reinterpret_cast<const char*>(b.data()), 10);
  }
  auto source = openRawFrames(dir.file("f.raw"), {size, PixelFormat::kRgba8, 0});
  ASSERT_TRUE(source);
  EXPECT_EQ((*source)->frameInterval(), std::nullopt);
  Frame f;
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  expectFrame(f, 0, size, 4);
  auto r = (*source)->read(f);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kIo);
  EXPECT_NE(r.error().message.find("partial frame"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("10 of 64 bytes"), std::string::npos) << r.error().message;
}

TEST(RawFrames, BadArguments) {
  TempDir dir;
  EXPECT_EQ(openRawFrames(dir.file("x"), {{1, 4}, PixelFormat::kRgb8, 0}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(openRawFrames(dir.file("x"), {{4, 4}, PixelFormat::kRgb8, -1}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(openRawFrames(dir.file("missing"), {{4, 4}, PixelFormat::kRgb8, 0}).error().code,
            ErrorCode::kIo);
  EXPECT_EQ(openRawFrames("/tmp", {{4, 4}, PixelFormat::kRgb8, 0}).error().code, ErrorCode::kIo);
  EXPECT_EQ(parsePixelFormat("rgba").value(), PixelFormat::kRgba8);
  EXPECT_FALSE(parsePixelFormat("yuyv"));
}

// The writer is driven from this thread in steps, so every state is deterministic.
TEST(RawFrames, FifoWaitsForWriterAssemblesFramesAndEndsWhenItCloses) {
  TempDir dir;
  const std::string path = dir.file("pipe");
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  const cv::Size size(3, 2);
  auto source = openRawFrames(path, {size, PixelFormat::kRgb8, 30});
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_GE((*source)->pollFd(), 0);
  EXPECT_EQ((*source)->frameInterval(), std::nullopt);  // paced by the writer
  Frame f;
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kNoFrame);  // no writer yet
  const int w = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  ASSERT_GE(w, 0);
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kNoFrame);  // writer, no bytes
  const auto f0 = frameBytes(0, size, 3);
  const auto f1 = frameBytes(1, size, 3);
  ASSERT_EQ(::write(w, f0.data(), 7), 7);
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kNoFrame);  // 7 of 18 bytes
  ASSERT_EQ(::write(w, f0.data() + 7, f0.size() - 7), ssize_t(f0.size() - 7));
  ASSERT_EQ(::write(w, f1.data(), f1.size()), ssize_t(f1.size()));
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  expectFrame(f, 0, size, 3);
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  expectFrame(f, 1, size, 3);
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kNoFrame);
  ::close(w);
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kEnd);
}

TEST(RawFrames, FifoWriterClosingMidFrameIsAnError) {
  TempDir dir;
  const std::string path = dir.file("pipe");
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  auto source = openRawFrames(path, {{2, 2}, PixelFormat::kRgba8, 0});
  ASSERT_TRUE(source);
  const int w = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  ASSERT_GE(w, 0);
  const uint8_t bytes[5] = {1, 2, 3, 4, 5};
  ASSERT_EQ(::write(w, bytes, 5), 5);
  ::close(w);
  Frame f;
  auto r = (*source)->read(f);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("5 of 16 bytes"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace procam::content
