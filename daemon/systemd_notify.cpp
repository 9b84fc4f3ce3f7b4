#include "systemd_notify.hpp"

#include <systemd/sd-daemon.h>

namespace procam::daemon {

void notifyReady(const std::string& status) {
  sd_notify(0, ("READY=1\nSTATUS=" + status).c_str());
}

void notifyStatus(const std::string& status) {
  sd_notify(0, ("STATUS=" + status).c_str());
}

void notifyStopping() {
  sd_notify(0, "STOPPING=1\nSTATUS=stopping");
}

void notifyWatchdog() {
  sd_notify(0, "WATCHDOG=1");
}

std::optional<std::chrono::microseconds> watchdogPingInterval() {
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) return std::nullopt;
  return std::chrono::microseconds(usec / 2);
}

}  // namespace procam::daemon
