#pragma once
// One thread that owns a GL context for its whole life: every call that touches an
// output's GL objects runs there, whichever thread asks. procamd opens devices on one
// thread, draws on another and destroys them on a third, while a context can be current on
// one thread only, and making it current and free again around every call costs ~0.25 ms
// per call on NVIDIA's driver (measured on an H100, keystoned 1080p frames through the
// output ABI: 0.88 ms per frame that way, 0.44 ms through this thread).
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>
#include <type_traits>

namespace procam::output::egl {

class GlThread {
 public:
  GlThread();
  ~GlThread();  // runs what is queued, then joins
  GlThread(const GlThread&) = delete;
  GlThread& operator=(const GlThread&) = delete;

  // Runs `f` on the thread and returns its result (an exception travels back).
  template <class F>
  std::invoke_result_t<F&> run(F&& f) {
    using R = std::invoke_result_t<F&>;
    if (std::this_thread::get_id() == thread_.get_id()) return f();
    std::packaged_task<R()> task(std::forward<F>(f));
    auto done = task.get_future();
    post([&task] { task(); });  // `task` outlives the job: this call waits for it
    return done.get();
  }

 private:
  void post(std::function<void()> job);
  void loop();

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> jobs_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace procam::output::egl
