// Shared-memory frames: exact pixels through a sealed memfd, refusal of unsealed,
// small, foreign or mismatched descriptors (without leaking them), and the
// seqlock never yielding a frame overwritten during the copy.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <filesystem>

#include "content/shm_frames.hpp"

namespace procam::content {
namespace {

size_t openFds() {
  size_t n = 0;
  for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

cv::Mat solid(cv::Size size, cv::Vec4b rgba, int marker) {
  cv::Mat m(size, CV_8UC4, cv::Scalar(rgba[0], rgba[1], rgba[2], rgba[3]));
  m.at<cv::Vec4b>(0, 0) = cv::Vec4b(uint8_t(marker), 0, 0, 255);
  return m;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(ShmFrames, TwoPublishedFramesReadBackExactly) {
  const cv::Size size(7, 5);
  auto producer = ShmFrameProducer::create(size, PixelFormat::kRgba8);
  ASSERT_TRUE(producer) << producer.error().message;
  auto source = openSharedFrames(::dup(producer->fd()), size, PixelFormat::kRgba8);
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->size(), size);
  Frame f;
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kNoFrame);  // nothing published
  const cv::Mat a = solid(size, {10, 20, 30, 255}, 1);
  const cv::Mat b = solid(size, {200, 100, 50, 128}, 2);
  producer->publish(a.data);
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  EXPECT_TRUE(same(f.pixels, a));
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kNoFrame);  // same frame again
  producer->publish(b.data);
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  EXPECT_TRUE(same(f.pixels, b));
  EXPECT_EQ(f.sequence, 2u);
}

// A frame the consumer still holds is never reused for the next one; one it
// released is.
TEST(ShmFrames, HeldFramesAreNotOverwritten) {
  const cv::Size size(4, 4);
  auto producer = ShmFrameProducer::create(size, PixelFormat::kRgba8);
  ASSERT_TRUE(producer);
  auto source = openSharedFrames(::dup(producer->fd()), size, PixelFormat::kRgba8);
  ASSERT_TRUE(source);
  std::vector<cv::Mat> held;
  for (int k = 0; k < 5; ++k) {
    const cv::Mat m = solid(size, {uint8_t(k), 0, 0, 255}, k);
    producer->publish(m.data);
    Frame f;
    ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
    held.push_back(f.pixels);
  }
  for (int k = 0; k < 5; ++k) {
    EXPECT_TRUE(same(held[size_t(k)], solid(size, {uint8_t(k), 0, 0, 255}, k))) << k;
  }
  const uint8_t* first = held[0].data;
  held.clear();  // all released: the next frame lands in a pooled buffer
  const cv::Mat m = solid(size, {9, 9, 9, 255}, 9);
  producer->publish(m.data);
  Frame f;
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  EXPECT_EQ(f.pixels.data, first);
  EXPECT_TRUE(same(f.pixels, m));
}

TEST(ShmFrames, RgbFramesToo) {
  const cv::Size size(3, 3);
  auto producer = ShmFrameProducer::create(size, PixelFormat::kRgb8);
  ASSERT_TRUE(producer);
  cv::Mat rgb(size, CV_8UC3);
  for (int i = 0; i < 27; ++i) rgb.data[i] = uint8_t(i * 9);
  producer->publish(rgb.data);
  auto source = openSharedFrames(::dup(producer->fd()), size, PixelFormat::kRgb8);
  ASSERT_TRUE(source) << source.error().message;
  Frame f;
  ASSERT_EQ((*source)->read(f).value(), ReadStatus::kFrame);
  EXPECT_TRUE(same(f.pixels, rgb));
}

// A reader that finds the producer writing the front buffer's successor keeps the
// published front; one whose buffer is rewritten during its copy refuses the copy.
TEST(ShmFrames, OverwrittenDuringCopyIsNeverShown) {
  const cv::Size size(16, 8);
  auto producer = ShmFrameProducer::create(size, PixelFormat::kRgba8);
  ASSERT_TRUE(producer);
  const cv::Mat a = solid(size, {1, 1, 1, 255}, 1);
  const cv::Mat b = solid(size, {2, 2, 2, 255}, 2);
  const cv::Mat c = solid(size, {3, 3, 3, 255}, 3);
  producer->publish(a.data);
  ShmFrameReader reader(producer->memory(), size, PixelFormat::kRgba8);

  // Producer half-way through the back buffer: the front (a) is still whole.
  uint8_t* back = producer->beginWrite();
  std::memcpy(back, b.data, b.total() * 4 / 2);
  cv::Mat out;
  ASSERT_TRUE(reader.copyNewest(out));
  EXPECT_TRUE(same(out, a));
  std::memcpy(back + b.total() * 4 / 2, b.data + b.total() * 4 / 2, b.total() * 4 / 2);
  producer->endWrite();  // front is now b

  // During the copy of b the producer publishes c (into a's old buffer) and starts
  // writing over b's buffer: that copy is dropped, and the retry yields c whole.
  auto lap = [&] {
    producer->publish(c.data);
    std::memset(producer->beginWrite(), 0xEE, 64);
  };
  EXPECT_FALSE(reader.copyNewest(out, 1, lap));
  // The lapped copy is gone; the next call takes the published front (c) whole.
  ASSERT_TRUE(reader.copyNewest(out));
  EXPECT_TRUE(same(out, c));

  // Within one call: the first attempt (c) is overwritten during its copy, the
  // retry takes the frame the producer published meanwhile (0xEE over b).
  cv::Mat ee = b.clone();
  std::memset(ee.data, 0xEE, 64);
  bool lapped = false;
  auto lap_once = [&] {
    if (std::exchange(lapped, true)) return;
    producer->endWrite();                           // publishes the 0xEE frame
    std::memset(producer->beginWrite(), 0xAB, 64);  // over c's buffer
  };
  ASSERT_TRUE(reader.copyNewest(out, 2, lap_once));
  EXPECT_TRUE(lapped);
  EXPECT_TRUE(same(out, ee));
  producer->endWrite();
}

TEST(ShmFrames, RefusesForeignUnsealedSmallAndMismatchedWithoutLeaking) {
  const cv::Size size(8, 8);
  const size_t before = openFds();

  // Not a memfd: a pipe.
  int p[2];
  ASSERT_EQ(::pipe2(p, O_CLOEXEC), 0);
  ::close(p[1]);
  auto r = openSharedFrames(p[0], size, PixelFormat::kRgba8);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("not a memfd"), std::string::npos) << r.error().message;

  // Unsealed memfd of the right size.
  int fd = ::memfd_create("t", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, off_t(shmTotalBytes(size, PixelFormat::kRgba8))), 0);
  r = openSharedFrames(fd, size, PixelFormat::kRgba8);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("not sealed"), std::string::npos) << r.error().message;

  // Sealed but one byte short.
  fd = ::memfd_create("t", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  ASSERT_EQ(::ftruncate(fd, off_t(shmTotalBytes(size, PixelFormat::kRgba8) - 1)), 0);
  ASSERT_EQ(::fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL), 0);
  r = openSharedFrames(fd, size, PixelFormat::kRgba8);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("too small"), std::string::npos) << r.error().message;

  // A producer's memfd asked for with another size (its header disagrees).
  auto producer = ShmFrameProducer::create({4, 4}, PixelFormat::kRgba8);
  ASSERT_TRUE(producer);
  r = openSharedFrames(::dup(producer->fd()), {4, 3}, PixelFormat::kRgba8);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("header"), std::string::npos) << r.error().message;
  r = openSharedFrames(::dup(producer->fd()), {1, 3}, PixelFormat::kRgba8);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);

  EXPECT_EQ(openFds(), before + 1);  // only the producer's own memfd
}

TEST(ShmFrames, LayoutIsAlignedAndSized) {
  EXPECT_EQ(shmFrameBytes({1920, 1080}, PixelFormat::kRgba8), 1920u * 1080 * 4);
  // 3x3 rgb8 = 27 bytes, padded to 64 per buffer.
  EXPECT_EQ(shmTotalBytes({3, 3}, PixelFormat::kRgb8), 4096u + 128);
}

}  // namespace
}  // namespace procam::content
