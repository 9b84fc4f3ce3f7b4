#include "sim/background_rows.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace procam::sim {
namespace {

std::atomic<bool> g_background{false};
constexpr int kBackgroundNice = 10;

}  // namespace

void setBackgroundRendering(bool on) {
  g_background.store(on, std::memory_order_relaxed);
}

bool backgroundRendering() {
  return g_background.load(std::memory_order_relaxed);
}

void forEachRowInBackground(int rows, const std::function<void(int)>& body) {
  const int threads =
      std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, std::max(rows, 1));
  std::atomic<int> next{0};
  std::mutex failure_mutex;
  std::exception_ptr failure;
  auto work = [&] {
    // Raising one's own nice value needs no privilege; failing to is harmless.
    (void)setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kBackgroundNice);
    for (int y = next.fetch_add(1); y < rows; y = next.fetch_add(1)) {
      try {
        body(y);
      } catch (...) {
        std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next.store(rows);
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    pool.reserve(static_cast<std::size_t>(threads));
    for (int i = 0; i < threads; ++i) pool.emplace_back(work);
  }  // joined
  if (failure) std::rethrow_exception(failure);
}

}  // namespace procam::sim
