#pragma once
// The daemon's log: one line per message on stderr with an sd-daemon priority
// prefix ("<3>") so that journald files it at the right level.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace procam::daemon {

enum class LogLevel { kError = 0, kWarning = 1, kInfo = 2, kDebug = 3 };

const char* logLevelName(LogLevel level);
Result<LogLevel> parseLogLevel(std::string_view text);

void setLogLevel(LogLevel level);
LogLevel logLevel();

// Thread-safe; messages above the current level are dropped.
void log(LogLevel level, std::string_view message);
inline void logError(std::string_view m) {
  log(LogLevel::kError, m);
}
inline void logWarning(std::string_view m) {
  log(LogLevel::kWarning, m);
}
inline void logInfo(std::string_view m) {
  log(LogLevel::kInfo, m);
}
inline void logDebug(std::string_view m) {
  log(LogLevel::kDebug, m);
}

// Lets a repeated message through at most `burst` times per interval and says
// how many were held back in between, so that a fault repeating thousands of
// times a second (accept failing with EMFILE, a device erroring on every read)
// cannot fill the journal. Not thread-safe: one per call site on one thread.
class LogThrottle {
 public:
  explicit LogThrottle(std::chrono::milliseconds interval = std::chrono::seconds(10),
                       uint64_t burst = 1)
      : interval_(interval), burst_(burst) {}
  // The line to log now (with the count held back since the last one), or
  // nullopt once `burst` lines went out within the interval.
  std::optional<std::string> pass(
      std::string_view message,
      std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

 private:
  std::chrono::milliseconds interval_;
  uint64_t burst_;
  std::optional<std::chrono::steady_clock::time_point> window_;  // start of the interval
  uint64_t passed_ = 0;  // lines let through in this interval
  uint64_t held_ = 0;
};

}  // namespace procam::daemon
