#pragma once
// The "replay" camera: a folder of images and an index.csv (file, timestamp) recorded
// from a rig, delivered as frames at the recorded rate (scaled by `speed`) or as fast
// as they are asked for (speed 0). The regression input of the daemon, like gpsd's logs.
// Format of index.csv: drivers/camera/README.md.
#include <optional>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "camera/convert.hpp"

namespace procam::camera {

struct ReplayEntry {
  std::string file;   // relative to the folder
  int64_t offset_ns;  // recorded timestamp minus the first one
};

// Parses index.csv text: kInvalid with the line number for a malformed line, a
// timestamp that is not finite or does not increase, or no frames at all.
Result<std::vector<ReplayEntry>> parseReplayIndex(const std::string& text);

struct ReplayOptions {
  std::string dir;
  double speed = 1.0;  // 1: recorded rate, 2: twice as fast, 0: as fast as asked
  bool loop = false;   // start over at the end instead of reporting the end (kNoDevice)
  std::optional<procam_pixel_format> pixel;  // default: the first image's natural format
};

class ReplayCamera final : public Camera {
 public:
  explicit ReplayCamera(ReplayOptions options);
  ~ReplayCamera() override;
  ReplayCamera(const ReplayCamera&) = delete;
  ReplayCamera& operator=(const ReplayCamera&) = delete;

  Result<void> start() override;
  void stop() override;
  FrameFormat format() const override { return format_; }
  // Frame i is due at start + offset_i / speed; its timestamp is start + offset_i, so
  // the recorded spacing survives any speed.
  Result<const Frame*> capture(int timeout_ms) override;
  Result<void> setControl(Control control, double value) override;
  // A timerfd that turns readable when the next frame is due.
  int pollFd() const override { return timer_fd_; }
  std::string name() const override { return "replay " + options_.dir; }

  std::size_t frameCount() const { return entries_.size(); }

 private:
  Result<void> load(std::size_t index, Frame& out);
  uint64_t dueNs(std::size_t index) const;
  void armTimer();

  ReplayOptions options_;
  std::vector<ReplayEntry> entries_;
  FrameFormat format_;
  std::size_t next_ = 0;
  uint64_t start_ns_ = 0;
  int timer_fd_ = -1;
  cv::Mat decoded_, storage_;
  Frame frame_;
};

}  // namespace procam::camera
