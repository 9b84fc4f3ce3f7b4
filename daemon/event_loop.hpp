#pragma once
// The daemon's single epoll loop: file descriptors, timers (timerfd), signals
// (signalfd) and closures posted from worker threads (eventfd). Handlers run
// on the loop thread only and must not block.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "core/error.hpp"
#include "core/unique_fd.hpp"

namespace procam::daemon {

class EventLoop {
 public:
  using Handler = std::function<void(uint32_t events)>;

  static Result<std::unique_ptr<EventLoop>> create();
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  // Watches `fd` (not owned) for `events` (EPOLLIN, EPOLLOUT...).
  Result<void> add(int fd, uint32_t events, Handler handler);
  Result<void> modify(int fd, uint32_t events);
  // Safe to call from inside any handler, including the fd's own.
  void remove(int fd);

  // A repeating (or one-shot) timer; returns its id for removeTimer().
  Result<int> addTimer(std::chrono::nanoseconds interval, bool repeat,
                       std::function<void()> callback);
  void removeTimer(int id);

  // Blocks `signals` for the whole process (call before starting threads) and
  // delivers them through a signalfd.
  Result<void> watchSignals(const std::vector<int>& signals, std::function<void(int)> callback);

  // Runs `fn` on the loop thread soon. Thread-safe.
  void post(std::function<void()> fn);

  // Runs until stop(); returns the code given to stop().
  int run();
  void stop(int code = 0);

  size_t watchedCount() const { return handlers_.size(); }

 private:
  EventLoop() = default;
  struct Entry {
    uint32_t generation;
    std::shared_ptr<Handler> handler;
  };
  void drainPosted();

  UniqueFd epoll_;
  UniqueFd wake_;  // eventfd for post()
  std::unordered_map<int, Entry> handlers_;
  std::unordered_map<int, UniqueFd> timers_;
  UniqueFd signal_fd_;
  uint32_t next_generation_ = 1;
  std::atomic<bool> running_{false};
  std::atomic<int> exit_code_{0};
  std::mutex posted_mutex_;
  std::vector<std::function<void()>> posted_;
};

}  // namespace procam::daemon
