#pragma once
// When a moving projector's keystone frame goes on the wall. The daemon chooses the time
// as it plans the frame (the longest recent drawing ahead; on the output's next vblank
// from then when it presents at vblank), asks the output to present no earlier
// (procam_plugin.h `present_at`), and predicts the orientation to that instant on the
// tilt sensor's clock. Pure.
#include <cstdint>
#include <deque>
#include <optional>

namespace procam::daemon {

// The longest lead a turn is predicted over: three 60 Hz frames. The prediction's error
// grows with the cube of the lead (a hand's jerk), 0.14 degrees at 50 ms for a fast
// turn; a frame shown later than this is late whatever is predicted.
constexpr double kMaxPredictionLead = 0.05;

// The tilt sensor's clock against CLOCK_MONOTONIC. A reading arrives some time after
// its timestamp: the least (arrival - timestamp) of the last kWindow readings is the
// clocks' offset plus the shortest delivery, which a timer-read or interrupt-driven
// sensor keeps well under a millisecond.
class SensorClock {
 public:
  static constexpr std::size_t kWindow = 256;

  void add(uint64_t arrival_ns, uint64_t timestamp_ns);
  // CLOCK_MONOTONIC - sensor clock, ns; nullopt before the first reading.
  std::optional<int64_t> offsetNs() const;
  // A CLOCK_MONOTONIC time on the sensor's clock, seconds; nullopt before the first reading.
  std::optional<double> sensorSeconds(uint64_t monotonic_ns) const;

 private:
  std::deque<int64_t> offsets_;  // oldest first
};

// How long frames take from being planned to being ready to show: the budget a frame
// is given is the kQuantile of the last kWindow frames plus kMargin. A frame over it is
// shown late. Not the longest: draws stall now and then (15-50 ms for 1-2 % of 5 ms CPU
// draws on a shared two-core machine, measured standalone), and a budget that long
// would hold every frame back by as much, where the reading-to-shown latency is to stay
// within a 60 Hz frame (a replay of a handheld tour's 642 draws: 7 % late at a median
// budget of 7.6 ms; the longest of the last 32 frames: 1 % late at 21 ms).
class DrawBudget {
 public:
  static constexpr std::size_t kWindow = 64;
  static constexpr double kQuantile = 0.9;
  static constexpr double kMargin = 0.001;   // s
  static constexpr double kInitial = 0.012;  // s, before the first frame
  static constexpr double kMax = 0.1;        // s: a longer drawing is not waited for

  // Seconds; negative or non-finite values are not counted.
  void add(double seconds);
  double budget() const;

 private:
  std::deque<double> recent_;
};

// The time a frame planned at `now_ns` with `budget_s` to draw is presented at: now +
// budget, or for an output presenting at vblank (period_ns > 0, a vblank known at
// last_vblank_ns) the first vblank at or after that. CLOCK_MONOTONIC ns.
uint64_t presentTarget(uint64_t now_ns, double budget_s, uint64_t period_ns,
                       uint64_t last_vblank_ns);

}  // namespace procam::daemon
