#pragma once
// Worker threads for work that may block or take long (pipelines, fsync,
// image decoding). A job runs on a worker and returns a completion that is
// posted back to the event loop, so results are only ever applied on the
// loop thread.
//
// Every job is answered: a job that throws has its failure handler posted
// instead of a completion, with the exception's message. Jobs are kept in one
// lane per owner (a client, or 0 for the daemon itself) and the lanes are
// served in turn, so one client's long queue delays another client's job by
// at most one job per thread.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "event_loop.hpp"

namespace procam::daemon {

class WorkerPool {
 public:
  using Completion = std::function<void()>;
  using Job = std::function<Completion()>;
  using Failure = std::function<void(const std::string& what)>;
  using Owner = uint64_t;

  WorkerPool(EventLoop& loop, int threads);
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  // Finishes running jobs and drops queued ones (runs them too once
  // runQueuedOnStop() was called); completions not yet posted are lost.
  ~WorkerPool();
  // For a pool whose jobs must not be lost (state writes): its destructor runs the
  // queued jobs first.
  void runQueuedOnStop() { run_queued_on_stop_ = true; }

  void submit(Job job, Failure on_failure = {}, Owner owner = 0);
  size_t queued() const;
  size_t queued(Owner owner) const;  // queued, not yet running

 private:
  struct Entry {
    Job job;
    Failure on_failure;
  };
  void run();

  EventLoop& loop_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::condition_variable idle_;  // queued_ reached 0
  std::map<Owner, std::deque<Entry>> lanes_;
  std::deque<Owner> turn_;  // owners with queued jobs, next first
  size_t queued_ = 0;
  bool stopping_ = false;
  bool run_queued_on_stop_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace procam::daemon
