#include "worker_pool.hpp"

#include <exception>

#include "log.hpp"

namespace procam::daemon {

WorkerPool::WorkerPool(EventLoop& loop, int threads) : loop_(loop) {
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { run(); });
}

WorkerPool::~WorkerPool() {
  {
    std::unique_lock lock(mutex_);
    if (run_queued_on_stop_) idle_.wait(lock, [this] { return queued_ == 0; });
    stopping_ = true;
    lanes_.clear();
    turn_.clear();
    queued_ = 0;
  }
  cv_.notify_all();
  for (auto& t : threads_) t.join();
}

void WorkerPool::submit(Job job, Failure on_failure, Owner owner) {
  {
    std::lock_guard lock(mutex_);
    auto& lane = lanes_[owner];
    if (lane.empty()) turn_.push_back(owner);
    lane.push_back({std::move(job), std::move(on_failure)});
    ++queued_;
  }
  cv_.notify_one();
}

size_t WorkerPool::queued() const {
  std::lock_guard lock(mutex_);
  return queued_;
}

size_t WorkerPool::queued(Owner owner) const {
  std::lock_guard lock(mutex_);
  auto it = lanes_.find(owner);
  return it == lanes_.end() ? 0 : it->second.size();
}

void WorkerPool::run() {
  for (;;) {
    Entry entry;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, [this] { return stopping_ || queued_ > 0; });
      if (stopping_) return;
      const Owner owner = turn_.front();
      turn_.pop_front();
      auto lane = lanes_.find(owner);
      entry = std::move(lane->second.front());
      lane->second.pop_front();
      --queued_;
      if (lane->second.empty()) {
        lanes_.erase(lane);
      } else {
        turn_.push_back(owner);  // its next job after the other owners' next
      }
      if (queued_ == 0) idle_.notify_all();
    }
    Completion done;
    std::string failure;
    bool threw = true;
    try {
      done = entry.job();
      threw = false;
    } catch (const std::exception& e) {
      failure = e.what();
    } catch (...) {
    }
    if (threw) {
      if (failure.empty()) failure = "unknown exception";
      logError("worker job failed: " + failure);
      if (entry.on_failure) {
        loop_.post([f = std::move(entry.on_failure), failure] { f(failure); });
      }
      continue;
    }
    if (done) loop_.post(std::move(done));
  }
}

}  // namespace procam::daemon
