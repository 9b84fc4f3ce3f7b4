#include "log.hpp"

#include <unistd.h>

#include <atomic>
#include <string>

namespace procam::daemon {

namespace {
std::atomic<LogLevel> g_level{LogLevel::kInfo};
constexpr const char* kNames[] = {"error", "warning", "info", "debug"};
constexpr int kSyslogPriority[] = {3, 4, 6, 7};  // LOG_ERR, LOG_WARNING, LOG_INFO, LOG_DEBUG
}  // namespace

const char* logLevelName(LogLevel level) {
  return kNames[static_cast<int>(level)];
}

Result<LogLevel> parseLogLevel(std::string_view text) {
  for (int i = 0; i < 4; ++i) {
    if (text == kNames[i]) return static_cast<LogLevel>(i);
  }
  return fail(ErrorCode::kInvalidInput,
              "unknown log level '" + std::string(text) + "' (error, warning, info, debug)");
}

void setLogLevel(LogLevel level) {
  g_level.store(level);
}
LogLevel logLevel() {
  return g_level.load();
}

void log(LogLevel level, std::string_view message) {
  if (level > g_level.load()) return;
  std::string line = "<" + std::to_string(kSyslogPriority[static_cast<int>(level)]) + ">";
  line += message;
  line += '\n';
  // One write() per line keeps lines from threads whole.
  ssize_t rc = ::write(STDERR_FILENO, line.data(), line.size());
  (void)rc;
}

std::optional<std::string> LogThrottle::pass(std::string_view message,
                                             std::chrono::steady_clock::time_point now) {
  if (!window_ || now - *window_ >= interval_) {
    window_ = now;
    passed_ = 0;
  }
  if (passed_ >= burst_) {
    ++held_;
    return std::nullopt;
  }
  ++passed_;
  std::string line(message);
  if (held_ > 0) line += " (" + std::to_string(held_) + " more like it not logged)";
  held_ = 0;
  return line;
}

}  // namespace procam::daemon
