#pragma once
// How long a tilt reading takes to reach the wall: from its arrival in the daemon to
// the output's show() returning with the frame drawn from the solution made of it
// (solve and draw on the compute worker, and any frame already in flight). Kept over
// the last kWindow frames; what `keystone` reports as `latency`.
#include <chrono>
#include <cstdint>
#include <deque>
#include <nlohmann/json.hpp>

namespace procam::daemon {

class KeystoneLatency {
 public:
  static constexpr std::size_t kWindow = 512;

  // One frame shown `seconds` after its reading arrived; negative or non-finite
  // values (a clock that stepped) are not counted.
  void add(double seconds);
  std::uint64_t frames() const { return frames_; }
  // The median over the last kWindow frames, seconds; 0 before the first.
  double median() const;
  // null before the first frame; else {frames, last_ms, median_ms, p95_ms, max_ms}, the
  // statistics over the last kWindow frames.
  nlohmann::json toJson() const;

 private:
  std::deque<double> recent_;  // seconds, oldest first
  std::uint64_t frames_ = 0;
};

}  // namespace procam::daemon
