#pragma once
// Scripted GPIO lines for the ball-switch driver.
#include <algorithm>
#include <deque>

#include "tilt/gpio/ball_switch.hpp"

namespace procam::tilt::testing {

constexpr std::uint64_t kMs = 1'000'000;

// Scripted lines with a simulated clock: waitEdge returns queued edges whose time has
// come, advancing the clock.
class ScriptedLines final : public GpioLines {
 public:
  std::vector<bool> initial = {true, true};
  std::deque<GpioEdge> edges;
  std::uint64_t now = 0;
  Result<std::vector<bool>> levels() override { return initial; }
  Result<std::optional<GpioEdge>> waitEdge(int timeout_ms) override {
    const std::uint64_t until = now + std::uint64_t(timeout_ms) * kMs;
    if (!edges.empty() && edges.front().timestamp_ns <= until) {
      GpioEdge e = edges.front();
      edges.pop_front();
      now = std::max(now, e.timestamp_ns);
      return std::optional<GpioEdge>(e);
    }
    now = until;
    return std::optional<GpioEdge>();
  }
  std::uint64_t nowNs() override { return now; }
};

}  // namespace procam::tilt::testing
