// The epoll loop: closures posted from other threads run on the loop thread,
// timers fire, removal inside a handler is safe, worker results come back.
#include <gtest/gtest.h>
#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "event_loop.hpp"
#include "log.hpp"
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

// A job that throws is answered through its failure handler, with the message,
// and the worker goes on with the next job.
TEST(WorkerPool, AThrowingJobIsAnsweredByItsFailureHandler) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  EventLoop& l = **loop;
  std::vector<std::string> failures;
  int done = 0;
  {
    WorkerPool pool(l, 1);
    pool.submit([]() -> WorkerPool::Completion { throw std::runtime_error("bad_alloc-like"); },
                [&](const std::string& what) { failures.push_back(what); });
    pool.submit([]() -> WorkerPool::Completion { throw 7; },
                [&](const std::string& what) { failures.push_back(what); });
    pool.submit([&l, &done] {
      return [&l, &done] {
        ++done;
        l.stop();
      };
    });
    l.run();
  }
  EXPECT_EQ(failures, (std::vector<std::string>{"bad_alloc-like", "unknown exception"}));
  EXPECT_EQ(done, 1);
}

// Owners are served in turn: one owner's long queue delays another's job by one job.
TEST(WorkerPool, OwnersAreServedInTurn) {
  auto loop = EventLoop::create();
  ASSERT_TRUE(loop);
  EventLoop& l = **loop;
  std::vector<int> order;  // owner of each job, in the order they ran
  std::mutex m;
  {
    WorkerPool pool(l, 1);
    std::promise<void> gate;
    std::shared_future<void> open = gate.get_future().share();
    pool.submit([open] {  // holds the worker while the queues fill
      open.wait();
      return WorkerPool::Completion();
    });
    auto job = [&](int owner) {
      return [&, owner] {
        std::lock_guard lock(m);
        order.push_back(owner);
        return WorkerPool::Completion();
      };
    };
    for (int i = 0; i < 100; ++i) pool.submit(job(1), {}, 1);
    pool.submit(job(2), {}, 2);
    EXPECT_EQ(pool.queued(1), 100u);
    EXPECT_EQ(pool.queued(2), 1u);
    gate.set_value();
    pool.submit([&l] { return [&l] { l.stop(); }; }, {}, 3);
    l.run();
  }
  ASSERT_GE(order.size(), 2u);
  const auto second = std::find(order.begin(), order.end(), 2);
  ASSERT_NE(second, order.end());
  EXPECT_LE(second - order.begin(), 1) << "owner 2 waited behind owner 1's queue";
}

TEST(LogThrottle, PassesABurstPerIntervalThenCountsWhatItHeld) {
  LogThrottle t(std::chrono::seconds(10), 2);
  const auto t0 = std::chrono::steady_clock::time_point{} + std::chrono::hours(1);
  EXPECT_EQ(t.pass("x", t0), "x");
  EXPECT_EQ(t.pass("x", t0 + std::chrono::seconds(1)), "x");
  for (int i = 0; i < 1000; ++i) EXPECT_FALSE(t.pass("x", t0 + std::chrono::seconds(2)));
  EXPECT_EQ(t.pass("x", t0 + std::chrono::seconds(11)), "x (1000 more like it not logged)");
  EXPECT_EQ(t.pass("x", t0 + std::chrono::seconds(12)), "x");
}

}  // namespace
}  // namespace procam::daemon
