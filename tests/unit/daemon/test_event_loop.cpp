// The epoll loop: closures posted from other threads run on the loop thread,
// timers fire, removal inside a handler is safe, worker results come back.
#include <gtest/gtest.h>
#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <thread>

#include "event_loop.hpp"
#include "worker_pool.hpp"

namespace procam::daemon {
namespace {

TEST(EventLoop, PostedClosuresFromManyThreadsAllRunOnLoopThread) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  EventLoop& l = **loop;
  int ran = 0;  // touched only on the loop thread
  std::thread::id loop_thread;
  constexpr int kThreads = 4, kEach = 250;
  std::vector<std::thread> threads;
  bool wrong_thread = false;
  l.post([&] { loop_thread = std::this_thread::get_id(); });
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < kEach; ++i) {
        l.post([&] {
          wrong_thread = wrong_thread || std::this_thread::get_id() != loop_thread;
          if (++ran == kThreads * kEach) l.stop(7);
        });
      }
    });
  }
  EXPECT_EQ(l.run(), 7);
  for (auto& t : threads) t.join();
  EXPECT_EQ(ran, kThreads * kEach);
  EXPECT_FALSE(wrong_thread);
}

TEST(EventLoop, RepeatingTimerAndOneShotTimer) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  EventLoop& l = **loop;
  int repeats = 0, once = 0;
  auto rep = l.addTimer(std::chrono::milliseconds(1), true, [&] {
    if (++repeats == 5) l.stop();
  });
  ASSERT_TRUE(rep);
  ASSERT_TRUE(l.addTimer(std::chrono::microseconds(10), false, [&] { ++once; }));
  l.run();
  EXPECT_EQ(repeats, 5);
  EXPECT_EQ(once, 1);
  l.removeTimer(*rep);
}

TEST(EventLoop, HandlerMayRemoveAnotherReadyFdInTheSameBatch) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  EventLoop& l = **loop;
  int a[2], b[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, a), 0);
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, b), 0);
  UniqueFd a0(a[0]), a1(a[1]), b0(b[0]), b1(b[1]);
  ASSERT_EQ(::write(a1.get(), "x", 1), 1);
  ASSERT_EQ(::write(b1.get(), "x", 1), 1);
  int calls = 0;
  // Whichever runs first removes both: the other must not run.
  auto handler = [&](uint32_t) {
    ++calls;
    l.remove(a0.get());
    l.remove(b0.get());
    l.post([&] { l.stop(); });
  };
  ASSERT_TRUE(l.add(a0.get(), EPOLLIN, handler));
  ASSERT_TRUE(l.add(b0.get(), EPOLLIN, handler));
  l.run();
  EXPECT_EQ(calls, 1);
}

TEST(WorkerPool, ResultsArePostedBackToTheLoop) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  EventLoop& l = **loop;
  std::vector<int> results;
  {
    WorkerPool pool(l, 2);
    for (int i = 0; i < 10; ++i) {
      pool.submit([&l, &results, i] {
        const int square = i * i;  // on a worker
        return [&l, &results, square] {
          results.push_back(square);  // on the loop
          if (results.size() == 10) l.stop();
        };
      });
    }
    l.run();
  }
  std::sort(results.begin(), results.end());
  EXPECT_EQ(results, (std::vector<int>{0, 1, 4, 9, 16, 25, 36, 49, 64, 81}));
}

}  // namespace
}  // namespace procam::daemon
