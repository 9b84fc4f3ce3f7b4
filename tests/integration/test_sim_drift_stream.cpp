// recalibrate = "on-drift" and "on-drift-silent" end to end while a stream plays
// (sim_drift_rig.hpp: wall_oblique, the truth at rest as the rig model): a stream's frame
// changes between camera frames, so under "on-drift" its checks are fiducial frames, shown
// between the stream's frames; "on-drift-silent", which shows none, holds a stream frame on
// the output for each check's capture.
#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <thread>

#include "sim_drift_rig.hpp"

namespace procam::itest {
namespace {

constexpr int kWidth = 1600, kHeight = 900;

// Raw RGB frames written into a FIFO in turn, `fps` a second (the daemon reads a FIFO
// whenever bytes arrive: the writer sets the pace); closing the FIFO ends the stream.
class FifoFrames {
 public:
  FifoFrames(const std::string& fifo, std::vector<cv::Mat> frames, double fps)
      : frames_(std::move(frames)), fps_(fps), thread_([this, fifo] { run(fifo); }) {}
  ~FifoFrames() {
    stop_ = true;
    thread_.join();
  }
  int written() const { return written_; }

 private:
  void run(const std::string& fifo) {
    // Opened once the daemon reads it (ENXIO before), not blocking on a reader gone.
    int fd = -1;
    while (!stop_ && fd < 0) {
      fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fd < 0) std::this_thread::sleep_for(20ms);
    }
    const auto start = Clock::now();
    for (std::size_t i = 0; fd >= 0 && !stop_; ++i) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(i / fps_)));
      const cv::Mat& f = frames_[i % frames_.size()];
      const std::size_t n = f.total() * f.elemSize();
      for (std::size_t done = 0; done < n && !stop_;) {
        pollfd p{fd, POLLOUT, 0};
        if (::poll(&p, 1, 100) <= 0) continue;
        const ssize_t k = ::write(fd, f.data + done, n - done);
        if (k < 0 && errno != EAGAIN && errno != EINTR) {
          stop_ = true;  // the daemon closed it
          break;
        }
        if (k > 0) done += std::size_t(k);
      }
      if (!stop_) ++written_;
    }
    if (fd >= 0) ::close(fd);
  }
  std::vector<cv::Mat> frames_;
  double fps_;
  std::atomic<bool> stop_{false};
  std::atomic<int> written_{0};
  std::thread thread_;
};

// Three textured frames (a natural image's spectrum, three seeds), RGB.
std::vector<cv::Mat> texturedFrames() {
  std::vector<cv::Mat> out;
  for (int seed : {11, 12, 13}) {
    cv::Mat rgb;
    cv::cvtColor(drift::texturedContent({kWidth, kHeight}, seed, {80, 27, 9}), rgb,
                 cv::COLOR_GRAY2RGB);
    out.push_back(rgb);
  }
  return out;
}

// `content stream` of raw RGB frames from a new FIFO in `dir`.
std::string streamFrom(Connection& c, const TempDir& dir) {
  const std::string fifo = contentFile(dir, "frames");
  EXPECT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto reply = c.call({{"cmd", "content"},
                       {"action", "stream"},
                       {"path", fifo},
                       {"width", kWidth},
                       {"height", kHeight},
                       {"format", "rgb8"}});
  EXPECT_TRUE(reply && (*reply)["class"] == "CONTENT") << (reply ? reply->dump() : "");
  return fifo;
}

// Frames of the stream read, and frames drawn on the outputs.
int contentFrames(Connection& c) {
  auto r = c.call({{"cmd", "content"}});
  return r ? (*r)["content"].value("frames", 0) : 0;
}
int framesDrawn(Connection& c) {
  auto r = c.call({{"cmd", "status"}});
  return r ? (*r)["outputs"].value("frames", 0) : 0;
}

// A stream of textured frames at 10 per second through the rig's keystone, checked every
// 2 s (BumpCourse: fiducial frames, or `held` frames): still, the checks find the output
// registered and nothing is corrected; the projector bumped 1 degree is found at the next
// check and corrected, and the stream plays on throughout.
void streamCourse(bool held) {
  std::signal(SIGPIPE, SIG_IGN);
  TempDir dir;
  BumpCourse r(dir, held);
  ASSERT_NO_FATAL_FAILURE(r.start());
  ASSERT_NO_FATAL_FAILURE(showContent(r.c, texturedContent(dir)));
  const std::string before = rigText(dir);
  FifoFrames frames(streamFrom(r.c, dir), texturedFrames(), 10.0);
  const int drawn_start = framesDrawn(r.c);
  const double stream_start = r.sceneTime();
  const std::string what = held ? "a stream, silent" : "a stream";
  const json still = r.still(dir, before, what);
  const int drawn_still = framesDrawn(r.c) - drawn_start;
  const double streamed_s = r.sceneTime() - stream_start;
  EXPECT_TRUE(still.value("content_streamed", false)) << still.dump();
  EXPECT_FALSE(still.contains("unavailable")) << still.dump();
  if (held) {
    std::printf("[ figures  ] the last held frame: capture %.3f s, its check %.3f s\n",
                still.value("capture_s", -1.0), still.value("check_s", -1.0));
    EXPECT_FALSE(still.contains("fiducial")) << still.dump();  // silent: none shown
    EXPECT_FALSE(still.value("too_plain", true)) << still.dump();
  }
  // The stream plays between the checks: at least a third of its 10 frames a second drawn
  // (each check holds the frames back while the virtual camera renders its capture, up to
  // a second on a loaded machine); not under the sanitizers, which draw slower than that.
  std::printf("[ figures  ] stream frames drawn: %d in %.1f s before the bump (%d read)\n",
              drawn_still, streamed_s, contentFrames(r.c));
  if (kSlowdown == 1) {
    EXPECT_GE(drawn_still, static_cast<int>(10.0 / 3.0 * streamed_s)) << streamed_s;
  }
  r.corrected(dir, what);
  const int drawn_end = framesDrawn(r.c) - drawn_start;
  std::printf("[ figures  ] stream frames drawn: %d in all\n", drawn_end);
  EXPECT_GT(drawn_end, drawn_still);
}

// "on-drift": the checks are fiducial frames shown between the stream's frames, the bump
// corrected from their tag corners.
TEST(SimDrift, StreamedContentIsCheckedWithFiducialFramesAndABumpCorrected) {
  streamCourse(false);
}

// "on-drift-silent" shows no fiducial frame: the stream's frame is held on the output for
// each check (the frame's latency to the camera and the capture) and compared as content
// is, the bump corrected from the content's tiles.
TEST(SimDrift, StreamedContentIsCheckedFromHeldFramesWhenSilent) {
  streamCourse(true);
}

// "on-drift-silent" with held frames off: a stream leaves the output unavailable, and
// nothing changes.
TEST(SimDrift, StreamedContentIsUnavailableWhenSilentWithoutHeldFrames) {
  std::signal(SIGPIPE, SIG_IGN);
  TempDir dir;
  const std::string scene_file = sceneWithEvents(dir, "");
  DaemonProcess d(
      dir, driftDaemon(dir, "on-drift-silent", scene_file, {}, "drift_stream_period_s = 0\n"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  ASSERT_NO_FATAL_FAILURE(showContent(c, texturedContent(dir)));
  const std::string before = rigText(dir);
  FifoFrames frames(streamFrom(c, dir), texturedFrames(), 10.0);
  EXPECT_TRUE(eventually([&] { return contentFrames(c) >= 2; }, 10s * kSlowdown));
  json dr;
  EXPECT_TRUE(eventually(
      [&] {
        dr = outputDrift(c);
        return dr.is_object() &&
               dr.value("unavailable", "").find("held frames are off") != std::string::npos;
      },
      10s * kSlowdown))
      << dr.dump();
  EXPECT_TRUE(dr.value("content_streamed", false)) << dr.dump();
  EXPECT_FALSE(dr.contains("fiducial")) << dr.dump();
  EXPECT_EQ(before, rigText(dir));
}

}  // namespace
}  // namespace procam::itest
