// The control server's descriptor handling: clients that would leave the process fewer
// than its headroom are refused with `busy`, and when accept() finds no descriptor at
// all the reserve one lets each waiting client hear `busy` instead of nothing.
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "control_server.hpp"
#include "control_socket.hpp"
#include "event_loop.hpp"

namespace procam::daemon {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

// UBSan tests whether memory is readable through a pipe before it checks a vptr: with no
// descriptor left it reports every virtual call as one through a bad vptr, so under the
// sanitizers (built together here) these cases say nothing about the server.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// A server on a socket in a fresh directory, run by hand with runFor().
struct Served {
  explicit Served(size_t headroom) {
    char tmpl[] = "/tmp/procam-server-XXXXXX";
    if (::mkdtemp(tmpl) == nullptr) return;
    dir = tmpl;
    auto l = EventLoop::create();
    if (!l) return;
    loop = std::move(*l);
    auto socket = openControlSocket(dir + "/control.sock", static_cast<gid_t>(-1));
    if (!socket) return;
    path = socket->path;
    ServerOptions options;
    options.release = "test";
    options.descriptor_headroom = headroom;
    server = std::make_unique<ControlServer>(
        *loop, std::move(socket->fd), options, [](ClientId, const proto::Request&) {},
        [](ClientId) {});
    if (!server->start()) server.reset();
  }
  ~Served() {
    server.reset();
    loop.reset();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
  bool ok() const { return server != nullptr; }
  // Runs the loop for `d`; the timer that ends it is armed before any descriptor runs out.
  Result<int> arm(std::chrono::milliseconds d) {
    return loop->addTimer(d, false, [this] { loop->stop(0); });
  }

  std::string dir, path;
  std::unique_ptr<EventLoop> loop;
  std::unique_ptr<ControlServer> server;
};

// A connected client socket, or -1.
UniqueFd connectTo(const std::string& path) {
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return fd;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return {};
  return fd;
}

// The first line the server sent, as JSON; nullopt when none came.
std::optional<json> firstLine(int fd) {
  std::string buf;
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 200) <= 0) return std::nullopt;
    char c[256];
    const ssize_t n = ::recv(fd, c, sizeof c, 0);
    if (n <= 0) return std::nullopt;
    buf.append(c, static_cast<size_t>(n));
    if (const auto nl = buf.find('\n'); nl != std::string::npos) {
      json j = json::parse(buf.substr(0, nl), nullptr, false);
      if (j.is_discarded()) return std::nullopt;
      return j;
    }
  }
}

// Lowers the soft descriptor limit for the scope and takes every descriptor left under
// it, so the process has none free; both undone at the end.
class NoDescriptorsLeft {
 public:
  NoDescriptorsLeft() {
    ::getrlimit(RLIMIT_NOFILE, &saved_);
    int highest = 0;
    for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
      highest = std::max(highest, std::stoi(e.path().filename().string()));
    }
    rlimit lower = saved_;
    lower.rlim_cur = static_cast<rlim_t>(highest + 1);
    lowered_ = ::setrlimit(RLIMIT_NOFILE, &lower) == 0;
    for (;;) {
      UniqueFd fd(::dup(0));
      if (!fd.valid()) break;
      held_.push_back(std::move(fd));
    }
    exhausted_ = errno == EMFILE;
  }
  ~NoDescriptorsLeft() {
    held_.clear();
    ::setrlimit(RLIMIT_NOFILE, &saved_);
  }
  bool ok() const { return lowered_ && exhausted_; }

 private:
  rlimit saved_{};
  bool lowered_ = false, exhausted_ = false;
  std::vector<UniqueFd> held_;
};

double processCpuSeconds() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

TEST(ControlServerDescriptors, AcceptWithoutADescriptorRefusesEachClientWithBusy) {
  if (kSanitized) GTEST_SKIP() << "runs without sanitizers (they need descriptors too)";
  Served s(0);  // no headroom: the clients take the descriptors to the last
  ASSERT_TRUE(s.ok());
  // Waiting in the backlog while the process has no descriptor free.
  std::vector<UniqueFd> clients;
  for (int i = 0; i < 6; ++i) {
    clients.push_back(connectTo(s.path));
    ASSERT_TRUE(clients.back().valid());
  }
  ASSERT_TRUE(s.arm(500ms));
  double cpu = 0;
  {
    NoDescriptorsLeft none;
    ASSERT_TRUE(none.ok());
    const double before = processCpuSeconds();
    s.loop->run();
    cpu = processCpuSeconds() - before;
  }
  int busy = 0;
  for (const UniqueFd& c : clients) {
    auto line = firstLine(c.get());
    ASSERT_TRUE(line) << "a client heard nothing";
    EXPECT_EQ(line->value("class", ""), "ERROR") << line->dump();
    busy += line->value("code", "") == "busy";
  }
  EXPECT_EQ(busy, 6);
  EXPECT_EQ(s.server->clientCount(), 0u);
  EXPECT_EQ(s.server->stats().refused, 6u);
  // Half a second with no descriptor: a loop that spun on the readable socket would
  // spend it all.
  EXPECT_LT(cpu, 0.1);
  // Descriptors back: the next client gets in.
  UniqueFd again = connectTo(s.path);
  ASSERT_TRUE(again.valid());
  ASSERT_TRUE(s.arm(200ms));
  s.loop->run();
  auto banner = firstLine(again.get());
  ASSERT_TRUE(banner);
  EXPECT_EQ(banner->value("class", ""), "VERSION") << banner->dump();
  EXPECT_EQ(s.server->clientCount(), 1u);
}

TEST(ControlServerDescriptors, AClientLeavingLessThanTheHeadroomIsRefusedWithBusy) {
  if (kSanitized) GTEST_SKIP() << "runs without sanitizers (they need descriptors too)";
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &saved), 0);
  Served s(0);
  ASSERT_TRUE(s.ok());
  ASSERT_TRUE(s.arm(300ms));
  UniqueFd first = connectTo(s.path);
  UniqueFd second = connectTo(s.path);
  ASSERT_TRUE(first.valid() && second.valid());
  int next_free = 0;
  {
    UniqueFd probe(::dup(0));
    ASSERT_TRUE(probe.valid());
    next_free = probe.get();
  }
  // Descriptors are given lowest first: the server's end of `first` takes next_free, of
  // `second` the one after it, the last under a limit just above them. A headroom of one
  // lets the first client in and refuses the second.
  rlimit lower = saved;
  lower.rlim_cur = static_cast<rlim_t>(next_free + 2);
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &lower), 0);
  ServerOptions options;
  options.release = "test";
  options.descriptor_headroom = 1;
  s.server->setOptions(options);  // reads the lowered limit
  s.loop->run();
  ::setrlimit(RLIMIT_NOFILE, &saved);
  auto a = firstLine(first.get());
  auto b = firstLine(second.get());
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->value("class", ""), "VERSION") << a->dump();
  EXPECT_EQ(b->value("code", ""), "busy") << b->dump();
  EXPECT_NE(b->value("message", "").find("descriptor"), std::string::npos) << b->dump();
  EXPECT_EQ(s.server->clientCount(), 1u);
}

}  // namespace
}  // namespace procam::daemon
