// Many clients at once, and clients that stop reading: they are dropped with
// a logged reason and never hold up the others.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdio>
#include <thread>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

DaemonProcess::Launch withConfig(const TempDir& dir, const std::string& toml) {
  dir.write("procamd.toml", toml);
  return DaemonProcess::Launch{{"--config", dir.file("procamd.toml")}, {}, -1, true};
}

TEST(Load, HundredConcurrentClientsAllServed) {
  TempDir dir;
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started());
  constexpr int kClients = 100, kRequestsEach = 5;
  std::vector<std::thread> threads;
  std::vector<int> answered(kClients, 0);
  std::vector<double> worst_ms(kClients, 0);
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] {
      Connection c(d.socketPath());
      if (!c.ok()) return;
      for (int r = 0; r < kRequestsEach; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        auto reply = c.call({{"cmd", "status"}, {"id", i * 100 + r}}, 20s);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        worst_ms[i] = std::max(worst_ms[i], ms);
        if (reply && (*reply)["class"] == "STATUS" && (*reply)["id"] == i * 100 + r) ++answered[i];
      }
    });
  }
  for (auto& t : threads) t.join();
  int total = 0;
  for (int a : answered) total += a;
  EXPECT_EQ(total, kClients * kRequestsEach);
  // Reported, not asserted (no timing in pass/fail tests).
  std::printf("[ figures  ] %d clients x %d requests: worst round trip %.1f ms\n", kClients,
              kRequestsEach, *std::max_element(worst_ms.begin(), worst_ms.end()));
}

// A client that floods requests without reading the replies is held back once half
// its queue bound is unread (its requests wait in the socket), so its queue stays
// bounded; it is dropped when the stall timeout passes, and the others keep going.
TEST(Load, FloodingNonReaderIsHeldBackThenDroppedAndOthersKeepGoing) {
  TempDir dir;
  DaemonProcess d(dir,
                  withConfig(dir, "[daemon]\nclient_queue_kib = 64\nclient_stall_timeout_s = 1\n"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection slow(d.socketPath()), fast(d.socketPath());
  ASSERT_TRUE(slow.ok() && fast.ok());
  // Never reads: 2000 status replies (~1 KB each) exceed socket buffers + 64 KiB.
  std::string flood;
  for (int i = 0; i < 2000; ++i) flood += "{\"cmd\":\"status\",\"id\":" + std::to_string(i) + "}\n";
  std::thread writer([&] { slow.sendRaw(flood); });  // may block once the daemon drops it
  int served = 0;
  double worst_ms = 0;
  for (int i = 0; i < 50; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = fast.call({{"cmd", "version"}, {"id", i}});
    worst_ms = std::max(
        worst_ms,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    served += r && (*r)["id"] == i;
  }
  EXPECT_EQ(served, 50);
  EXPECT_TRUE(eventually([&] { return d.log().find("stopped reading for") != std::string::npos; }))
      << d.log();
  EXPECT_EQ(d.log().find("output queue over"), std::string::npos) << d.log();
  EXPECT_TRUE(slow.closedByPeer());
  ::shutdown(slow.fd(), SHUT_RDWR);
  writer.join();
  auto s = fast.call({{"cmd", "status"}});
  ASSERT_TRUE(s);
  EXPECT_EQ((*s)["clients"], 1);
  std::printf("[ figures  ] fast client beside a flooding non-reader: worst round trip %.1f ms\n",
              worst_ms);
}

TEST(Load, ClientThatStopsReadingIsDroppedAfterTheStallTimeout) {
  TempDir dir;
  DaemonProcess d(dir, withConfig(dir, "[daemon]\nclient_stall_timeout_s = 0.3\n"));
  ASSERT_TRUE(d.started()) << d.log();
  Connection stuck(d.socketPath()), fast(d.socketPath());
  // ~450 KB of replies it never reads: the socket buffer takes ~200 KB, the
  // rest stays queued (under the 1 MiB bound) without progress.
  std::string burst;
  for (int i = 0; i < 500; ++i) burst += "{\"cmd\":\"status\",\"id\":" + std::to_string(i) + "}\n";
  ASSERT_TRUE(stuck.sendRaw(burst));
  EXPECT_TRUE(eventually([&] { return d.log().find("stopped reading for") != std::string::npos; }))
      << d.log();
  EXPECT_TRUE(stuck.closedByPeer());
  EXPECT_EQ((*fast.call({{"cmd", "status"}}))["clients"], 1);
}

TEST(Load, ClientLimitRefusesExtraConnectionsWithBusy) {
  TempDir dir;
  DaemonProcess d(dir, withConfig(dir, "[daemon]\nmax_clients = 3\n"));
  ASSERT_TRUE(d.started());
  // started() probed with a connection that closed: wait until the daemon has
  // seen it go, so that exactly the held connections count.
  std::vector<Connection> held;
  held.emplace_back(d.socketPath());
  ASSERT_TRUE(eventually([&] {
    auto s = held[0].call({{"cmd", "status"}});
    return s && (*s)["clients"] == 1;
  }));
  held.emplace_back(d.socketPath());
  held.emplace_back(d.socketPath());
  for (auto& h : held) ASSERT_EQ(h.banner()["class"], "VERSION");
  Connection extra(d.socketPath());
  ASSERT_TRUE(extra.ok());
  EXPECT_EQ(extra.banner()["class"], "ERROR");
  EXPECT_EQ(extra.banner()["code"], "busy");
  EXPECT_TRUE(extra.closedByPeer());
}

}  // namespace
}  // namespace procam::itest
