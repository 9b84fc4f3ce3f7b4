#pragma once
// The daemon's log: one line per message on stderr with an sd-daemon priority
// prefix ("<3>") so that journald files it at the right level.
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

}  // namespace procam::daemon
