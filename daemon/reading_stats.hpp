#pragma once
// What the daemon measured of a device it reads (cameras and trackers in
// `devices`): readings so far, the rate they arrive at, the last timestamp.
// The rate is measured on the daemon's clock, over the arrivals of the last
// two seconds, so it shows how fast readings really come in (a replayed
// recording delivered at its recorded rate, a tracker at its sample rate).
#include <chrono>
#include <cstdint>
#include <deque>
#include <nlohmann/json.hpp>

namespace procam::daemon {

class ReadingStats {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kWindow{2};

  // One reading with the device's timestamp (ns); a repeated timestamp is the
  // same reading read twice and is not counted. False when it was not counted.
  bool add(uint64_t timestamp_ns, Clock::time_point arrived = Clock::now());

  uint64_t count() const { return count_; }
  uint64_t lastTimestampNs() const { return last_ns_; }
  // Readings per second over the window ending at `now`; 0 with fewer than two.
  double rateHz(Clock::time_point now = Clock::now()) const;
  // {<count_key>: n, "rate_hz": r, "last_timestamp": seconds} (the device's clock).
  nlohmann::json toJson(const char* count_key) const;

 private:
  uint64_t count_ = 0;
  uint64_t last_ns_ = 0;
  std::deque<Clock::time_point> arrivals_;  // within kWindow of the newest
};

}  // namespace procam::daemon
