#pragma once
// The one virtual world the mock drivers of a process share: every mock
// device opened on the same scene sees the frames the mock outputs show, on a
// common clock (seconds since the world was first opened). Shown frames are kept
// with their show times for cameras with a display-to-capture latency
// (CameraSpec::latency_s).
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "sim/renderer.hpp"
#include "sim/scene.hpp"

namespace procam::sim::mock {

class SimWorld {
 public:
  // At most this many frames are kept per projector, however fast they are shown.
  static constexpr std::size_t kMaxKeptFrames = 64;

  // The world of a scene (a shipped scene's name or a file), created on first use.
  static Result<std::shared_ptr<SimWorld>> open(const std::string& scene);

  const Scene& scene() const { return scene_; }
  double now() const;
  // A world time on CLOCK_MONOTONIC (ns), the camera frames' clock.
  uint64_t monotonicNs(double world_time) const;
  // The world time of a CLOCK_MONOTONIC time (ns).
  double worldTime(uint64_t monotonic_ns) const;

  // Shows `framebuffer` on `projector` from world time `at` on (now when not given or
  // past; never before a frame shown before it). Returns the time it goes on.
  double show(const std::string& projector, cv::Mat framebuffer,
              std::optional<double> at = std::nullopt);
  // What the projectors show now, and how many frames have gone on so far (it changes
  // with every frame that goes on: a camera's view of a still scene is the same between
  // two equal counts).
  Framebuffers shown() const;
  std::uint64_t showCount() const;
  // What they showed at world time `t` (a projector that had shown nothing yet is
  // absent); older than the kept history: the oldest frame kept.
  Framebuffers shownAt(double t) const;

  explicit SimWorld(Scene scene);

 private:
  struct Shown {
    double time;
    cv::Mat frame;
  };
  Scene scene_;
  double keep_s_ = 0;  // history length: the largest camera latency, plus slack
  std::chrono::steady_clock::time_point epoch_ = std::chrono::steady_clock::now();
  mutable std::mutex mutex_;
  struct History {
    std::deque<Shown> frames;  // oldest first
    bool trimmed = false;      // frames were dropped from its front
  };
  std::map<std::string, History, std::less<>> history_;
  std::uint64_t shows_ = 0;
};

}  // namespace procam::sim::mock
