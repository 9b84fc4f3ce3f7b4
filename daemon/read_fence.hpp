#pragma once
// The hand-over of a device between the device manager's reader worker and an
// operation that drives the device on its own worker (calibrate, latency).
// Every tracker or camera read the manager hands to its reader carries a
// ReadTicket. When the operation closes the read gate (on the loop), the
// manager withdraws the tickets of those devices and returns a ReadFence; the
// operation's worker waits on it before its first driver call, so a read
// already running finishes first and one still queued never starts.
#include <condition_variable>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace procam::daemon {

class ReadTicket {
 public:
  // Reader worker, before the driver call: false when the read was withdrawn.
  bool begin() {
    std::lock_guard lock(mutex_);
    if (withdrawn_) return false;
    running_ = true;
    return true;
  }
  // Reader worker, after the driver call.
  void end() {
    {
      std::lock_guard lock(mutex_);
      running_ = false;
    }
    done_.notify_all();
  }
  // Loop: a read not started yet will not start. The lock guards two flags
  // only (never the driver call), so the loop never waits on a device.
  void withdraw() {
    std::lock_guard lock(mutex_);
    withdrawn_ = true;
  }
  // Blocks until the driver call is over; after withdraw() none follows.
  void wait() {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return !running_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable done_;
  bool running_ = false;
  bool withdrawn_ = false;
};

class ReadFence {
 public:
  ReadFence() = default;
  explicit ReadFence(std::vector<std::shared_ptr<ReadTicket>> tickets)
      : tickets_(std::move(tickets)) {}
  // On the operation's worker (never the loop): returns once none of the
  // fenced devices is being read by the manager.
  void wait() const {
    for (const auto& t : tickets_) t->wait();
  }
  size_t size() const { return tickets_.size(); }

 private:
  std::vector<std::shared_ptr<ReadTicket>> tickets_;
};

}  // namespace procam::daemon
