// The replay camera on a temporary folder of PNGs, directly and through the plugin ABI.
#include <gtest/gtest.h>
#include <poll.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "camera/plugin/camera_plugin.hpp"
#include "camera/replay/replay_camera.hpp"

namespace procam::camera {
namespace {

namespace fs = std::filesystem;

// A folder of `n` 8x6 gray PNGs whose pixels all equal 10 * i, recorded `spacing_s` apart.
class Recording {
 public:
  Recording(int n, double spacing_s, int depth = CV_8U) {
    dir_ = fs::temp_directory_path() /
           ("procam-replay-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    fs::create_directories(dir_);
    std::ofstream index(dir_ / "index.csv");
    index << "file,timestamp\n# recorded by hand\n";
    for (int i = 0; i < n; ++i) {
      const std::string name = "frame" + std::to_string(i) + ".png";
      const double value = depth == CV_16U ? 1000.0 * i + 7 : 10.0 * i;
      cv::imwrite((dir_ / name).string(), cv::Mat(6, 8, depth, cv::Scalar(value)));
      index << name << "," << std::to_string(100.0 + i * spacing_s) << "\n";
    }
  }
  ~Recording() { fs::remove_all(dir_); }
  std::string dir() const { return dir_.string(); }

 private:
  static inline int counter_ = 0;
  fs::path dir_;
};

TEST(ReplayIndex, ParsesHeaderCommentsAndOffsets) {
  auto r = parseReplayIndex("file,timestamp\n# c\n a.png , 10.5\nb.png,10.75\n\n");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[0].file, "a.png");
  EXPECT_EQ((*r)[0].offset_ns, 0);
  EXPECT_EQ((*r)[1].offset_ns, 250'000'000);
}

TEST(ReplayIndex, RefusesBadLines) {
  for (const char* text :
       {"a.png,1\nb.png,1\n", "a.png,x\n", "a.png\n", "file,timestamp\n", "a.png,nan\n"}) {
    auto r = parseReplayIndex(text);
    ASSERT_FALSE(r) << text;
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
  }
  EXPECT_NE(parseReplayIndex("a.png,2\nb.png,1\n").error().message.find("line 2"),
            std::string::npos);
}

TEST(Replay, DeliversEveryFrameInOrderThenReportsTheEnd) {
  Recording rec(5, 0.04);
  ReplayCamera cam({rec.dir(), 0.0, false, std::nullopt});
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.format().width, 8u);
  EXPECT_EQ(cam.format().height, 6u);
  EXPECT_EQ(cam.format().pixel, PROCAM_PIXEL_GRAY8);
  uint64_t first = 0;
  for (int i = 0; i < 5; ++i) {
    auto f = cam.capture(0);  // speed 0: every frame is due at once
    ASSERT_TRUE(f) << f.error().message;
    EXPECT_EQ((*f)->image.at<uint8_t>(3, 4), 10 * i);
    if (i == 0) first = (*f)->timestamp_ns;
    // The recorded spacing (40 ms) survives exactly.
    EXPECT_EQ((*f)->timestamp_ns - first, uint64_t(i) * 40'000'000u);
  }
  // The end is announced on the poll fd too, so a reader waiting on it learns of it.
  pollfd p{cam.pollFd(), POLLIN, 0};
  EXPECT_EQ(::poll(&p, 1, 1000), 1);
  auto end = cam.capture(0);
  ASSERT_FALSE(end);
  EXPECT_EQ(end.error().code, ErrorCode::kEnded);
  EXPECT_NE(end.error().message.find("end of the recording"), std::string::npos);
}

TEST(Replay, WaitsForTheRecordedTime) {
  Recording rec(2, 0.3);
  ReplayCamera cam({rec.dir(), 1.0, false, std::nullopt});
  ASSERT_TRUE(cam.start());
  ASSERT_TRUE(cam.capture(0));
  // The second frame is 300 ms later: not there yet, and the timer fd is not readable.
  auto early = cam.capture(0);
  ASSERT_FALSE(early);
  EXPECT_EQ(early.error().code, ErrorCode::kAgain);
  pollfd p{cam.pollFd(), POLLIN, 0};
  EXPECT_EQ(::poll(&p, 1, 0), 0);
  EXPECT_EQ(cam.capture(10).error().code, ErrorCode::kTimeout);
  // It becomes readable when the frame is due; then the frame is there without waiting.
  ASSERT_EQ(::poll(&p, 1, 2000), 1);
  auto f = cam.capture(0);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ((*f)->image.at<uint8_t>(0, 0), 10);
  EXPECT_GE(monotonicNs(), (*f)->timestamp_ns);
}

TEST(Replay, LoopsWhenAsked) {
  Recording rec(2, 0.01);
  ReplayCamera cam({rec.dir(), 0.0, true, std::nullopt});
  ASSERT_TRUE(cam.start());
  std::vector<int> seen;
  for (int i = 0; i < 5; ++i) {
    auto f = cam.capture(0);
    ASSERT_TRUE(f) << f.error().message;
    seen.push_back((*f)->image.at<uint8_t>(0, 0));
  }
  EXPECT_EQ(seen, (std::vector<int>{0, 10, 0, 10, 0}));
}

TEST(Replay, SixteenBitFramesKeepTheirValues) {
  Recording rec(2, 0.01, CV_16U);
  ReplayCamera cam({rec.dir(), 0.0, false, std::nullopt});
  ASSERT_TRUE(cam.start());
  EXPECT_EQ(cam.format().pixel, PROCAM_PIXEL_GRAY16);
  ASSERT_TRUE(cam.capture(0));
  auto f = cam.capture(0);
  ASSERT_TRUE(f);
  EXPECT_EQ((*f)->image.at<uint16_t>(5, 7), 1007);
}

TEST(Replay, MissingFolderAndMismatchedImages) {
  ReplayCamera none({"/nonexistent/procam-replay", 1.0, false, std::nullopt});
  auto r = none.start();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kNoDevice);

  Recording rec(2, 0.01);
  cv::imwrite(rec.dir() + "/frame1.png", cv::Mat(7, 8, CV_8U, cv::Scalar(1)));
  ReplayCamera cam({rec.dir(), 0.0, false, std::nullopt});
  ASSERT_TRUE(cam.start());
  ASSERT_TRUE(cam.capture(0));
  auto bad = cam.capture(0);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kInvalidInput);
  EXPECT_NE(bad.error().message.find("8x7"), std::string::npos);
}

// --- the plugin ABI ---

const procam_driver_factory* factory(const char* name) {
  const procam_plugin_table* t = procam_camera_plugin_entry();
  for (std::size_t i = 0; i < t->n_factories; ++i)
    if (std::string(t->factories[i].name) == name) return &t->factories[i];
  return nullptr;
}

TEST(ReplayPlugin, ProbeCreateCaptureAndRefusedControls) {
  const procam_driver_factory* f = factory("replay");
  ASSERT_NE(f, nullptr);
  Recording rec(3, 0.01);
  procam_device_desc udev{
      PROCAM_FAMILY_CAMERA, "video4linux", "/dev/video0", nullptr, nullptr, nullptr, 0};
  EXPECT_EQ(f->probe(&udev), 0);  // a V4L2 node is not a recording
  procam_device_desc desc{PROCAM_FAMILY_CAMERA, "replay", nullptr, nullptr, "rec", nullptr, 0};
  EXPECT_EQ(f->probe(&desc), 90);

  const std::string dir = rec.dir();
  const procam_kv opts[] = {{"dir", dir.c_str()}, {"speed", "0"}, {"pixel", "rgb8"}};
  procam_config config{opts, 3};
  procam_device dev{};
  char err[256] = {};
  ASSERT_EQ(f->create(&desc, &config, &dev, err, sizeof err), PROCAM_OK) << err;
  uint32_t w = 0, h = 0;
  procam_pixel_format pf{};
  ASSERT_EQ(dev.ops.camera->get_format(dev.self, &w, &h, &pf), PROCAM_OK);
  EXPECT_EQ(w, 8u);
  EXPECT_EQ(h, 6u);
  EXPECT_EQ(pf, PROCAM_PIXEL_RGB8);
  EXPECT_GE(dev.poll_fd(dev.self), 0);
  procam_image img{};
  ASSERT_EQ(dev.ops.camera->capture(dev.self, 0, &img, err, sizeof err), PROCAM_OK) << err;
  ASSERT_EQ(dev.ops.camera->capture(dev.self, 0, &img, err, sizeof err), PROCAM_OK) << err;
  EXPECT_EQ(img.format, PROCAM_PIXEL_RGB8);
  EXPECT_EQ(img.stride, 24u);
  EXPECT_EQ(img.data[5 * 24 + 3], 10);  // gray 10 in every channel
  EXPECT_EQ(dev.ops.camera->set_exposure(dev.self, 0.01, err, sizeof err), PROCAM_ENOTSUP);
  EXPECT_NE(std::string(err).find("not supported by this device"), std::string::npos);
  dev.destroy(dev.self);

  // A control in the configuration the recording cannot honour refuses the device.
  const procam_kv locked[] = {{"dir", dir.c_str()}, {"exposure_s", "0.01"}};
  procam_config lockedConfig{locked, 2};
  EXPECT_EQ(f->create(&desc, &lockedConfig, &dev, err, sizeof err), PROCAM_ENOTSUP);
  const procam_kv unknown[] = {{"dir", dir.c_str()}, {"fps", "30"}};
  procam_config unknownConfig{unknown, 2};
  EXPECT_EQ(f->create(&desc, &unknownConfig, &dev, err, sizeof err), PROCAM_EINVAL);
  EXPECT_NE(std::string(err).find("'fps'"), std::string::npos);
}

}  // namespace
}  // namespace procam::camera
