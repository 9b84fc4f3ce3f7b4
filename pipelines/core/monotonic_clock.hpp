#pragma once
// CLOCK_MONOTONIC in nanoseconds, the clock the plugin ABI's timestamps use
// (procam_plugin.h): std::chrono::steady_clock is CLOCK_MONOTONIC on Linux.
#include <chrono>
#include <cstdint>

namespace procam {

inline uint64_t monotonicNs(std::chrono::steady_clock::time_point t) {
  return static_cast<uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

inline uint64_t monotonicNowNs() {
  return monotonicNs(std::chrono::steady_clock::now());
}

}  // namespace procam
