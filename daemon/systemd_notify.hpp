#pragma once
// sd_notify(): READY, STATUS, STOPPING and watchdog pings. Harmless when not
// started by systemd (NOTIFY_SOCKET unset).
#include <chrono>
#include <optional>
#include <string>

namespace procam::daemon {

void notifyReady(const std::string& status);
void notifyStatus(const std::string& status);
void notifyStopping();
void notifyWatchdog();
// The interval at which to ping (half of WatchdogSec), when the watchdog is on.
std::optional<std::chrono::microseconds> watchdogPingInterval();

}  // namespace procam::daemon
