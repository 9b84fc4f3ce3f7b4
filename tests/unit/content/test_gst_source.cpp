// GStreamer video through appsink: exact pixels, sizes, frame rate and
// timestamps from videotestsrc and from a small AVI file made here (raw BGR
// frames, so decoding is lossless); the refusals (missing file, bad pipeline,
// not a video).
#include <gst/gst.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "content/gst_source.hpp"

namespace procam::content {
namespace {

// Reads until the end of the stream (or an error, or 20 s without one).
std::vector<Frame> readAll(ContentSource& source, std::string* error = nullptr) {
  std::vector<Frame> frames;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    Frame f;
    auto r = source.read(f);
    if (!r) {
      if (error) *error = r.error().message;
      break;
    }
    if (*r == ReadStatus::kEnd) break;
    if (*r == ReadStatus::kFrame) {
      frames.push_back(f);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  return frames;
}

GstOptions offline() {
  GstOptions o;
  o.realtime = false;
  return o;
}

TEST(GstSource, TestSourceFramesAreExact) {
  auto source = openGstPipeline(
      "videotestsrc num-buffers=3 pattern=solid-color foreground-color=0xff102030 "
      "! video/x-raw,format=RGBA,width=64,height=48,framerate=30/1",
      offline());
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->size(), cv::Size(64, 48));
  EXPECT_EQ((*source)->format(), PixelFormat::kRgba8);
  EXPECT_EQ((*source)->frameInterval(), std::chrono::nanoseconds(33'333'333));
  const auto frames = readAll(**source);
  ASSERT_EQ(frames.size(), 3u);
  for (size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat& p = frames[i].pixels;
    ASSERT_EQ(p.type(), CV_8UC4);
    ASSERT_EQ(p.size(), cv::Size(64, 48));
    cv::Mat diff;
    cv::absdiff(p, cv::Scalar(0x10, 0x20, 0x30, 0xff), diff);
    EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0) << "frame " << i;
    EXPECT_EQ(frames[i].sequence, i + 1);
    // Presentation times: i / 30 s, in whole nanoseconds as GStreamer rounds them.
    EXPECT_EQ(frames[i].timestamp.count(),
              static_cast<int64_t>(gst_util_uint64_scale(i, GST_SECOND, 30)));
  }
  Frame f;
  EXPECT_EQ((*source)->read(f).value(), ReadStatus::kEnd);
}

// An odd width: the RGB rows videoconvert reads are padded to 4 bytes (15 -> 16);
// the frame comes out packed RGBA.
TEST(GstSource, OddWidthsArePacked) {
  auto source = openGstPipeline(
      "videotestsrc num-buffers=1 pattern=solid-color foreground-color=0xff0000ff "
      "! video/x-raw,format=RGB,width=5,height=3",
      offline());
  ASSERT_TRUE(source) << source.error().message;
  const auto frames = readAll(**source);
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].pixels.size(), cv::Size(5, 3));
  ASSERT_TRUE(frames[0].pixels.isContinuous());
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x)
      EXPECT_EQ(frames[0].pixels.at<cv::Vec4b>(y, x), cv::Vec4b(0, 0, 255, 255));
  }
}

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/procam-gst-XXXXXX";
    path_ = ::mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// Runs a gst-launch description to its end; the error message, or empty.
std::string runPipeline(const std::string& description) {
  GError* error = nullptr;
  GstElement* p = gst_parse_launch(description.c_str(), &error);
  if (!p || error) return error ? error->message : "does not parse";
  gst_element_set_state(p, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(p);
  GstMessage* m = gst_bus_timed_pop_filtered(
      bus, 20 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  std::string result = !m ? "timeout" : GST_MESSAGE_TYPE(m) == GST_MESSAGE_ERROR ? "error" : "";
  if (m) gst_message_unref(m);
  gst_object_unref(bus);
  gst_element_set_state(p, GST_STATE_NULL);
  gst_object_unref(p);
  return result;
}

TEST(GstSource, SmallAviFileDecodesExactly) {
  TempDir dir;
  const std::string path = dir.file("clip with space.avi");
  gst_init(nullptr, nullptr);
  ASSERT_EQ(runPipeline("videotestsrc num-buffers=5 pattern=solid-color "
                        "foreground-color=0xff4080c0 ! video/x-raw,width=32,height=16,"
                        "framerate=10/1,format=BGR ! avimux ! filesink location=\"" +
                        path + "\""),
            "");
  auto source = openVideoFile(path, offline());
  ASSERT_TRUE(source) << source.error().message;
  EXPECT_EQ((*source)->size(), cv::Size(32, 16));
  EXPECT_EQ((*source)->frameInterval(), std::chrono::nanoseconds(100'000'000));
  const auto frames = readAll(**source);
  ASSERT_EQ(frames.size(), 5u);
  for (size_t i = 0; i < frames.size(); ++i) {
    cv::Mat diff;
    cv::absdiff(frames[i].pixels, cv::Scalar(0x40, 0x80, 0xc0, 0xff), diff);
    EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0) << "frame " << i;
    EXPECT_EQ(frames[i].timestamp, std::chrono::milliseconds(100) * static_cast<int64_t>(i));
  }
}

TEST(GstSource, Refusals) {
  TempDir dir;
  auto missing = openVideoFile(dir.file("none.mp4"), offline());
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);

  auto bad = openGstPipeline("no_such_element_here", offline());
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);

  std::ofstream(dir.file("text.avi")) << "not a video at all\n";
  auto text = openVideoFile(dir.file("text.avi"), offline());
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().code, ErrorCode::kIo);
  EXPECT_NE(text.error().message.find("text.avi"), std::string::npos) << text.error().message;
}

}  // namespace
}  // namespace procam::content
