#pragma once
// Worker threads for work that may block or take long (pipelines, fsync,
// image decoding). A job runs on a worker and returns a completion that is
// posted back to the event loop, so results are only ever applied on the
// loop thread.
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "event_loop.hpp"

namespace procam::daemon {

class WorkerPool {
 public:
  using Completion = std::function<void()>;
  using Job = std::function<Completion()>;

  WorkerPool(EventLoop& loop, int threads);
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  // Finishes running jobs, drops queued ones; completions not yet posted are lost.
  ~WorkerPool();

  void submit(Job job);
  size_t queued() const;

 private:
  void run();

  EventLoop& loop_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Job> jobs_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace procam::daemon
