// Start, stop and restart: persisted state across kill -9, corrupt state,
// stale and busy sockets, socket activation, sd_notify, peer credentials.
#include <grp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

const json kCorners = {{12.5, 8}, {1901, 16}, {1880, 1071}, {4, 1066}};

int boundUnixSocket(const std::string& path, bool listen_too) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return -1;
  if (listen_too && ::listen(fd, 16) != 0) return -1;
  return fd;
}

TEST(Lifecycle, SaveThenKill9ThenRestartKeepsState) {
  TempDir dir;
  {
    DaemonProcess d(dir);
    ASSERT_TRUE(d.started()) << d.log();
    Connection c(d.socketPath());
    ASSERT_EQ((*c.call({{"cmd", "keystone"}, {"action", "set"}, {"corners", kCorners}}))["class"],
              "KEYSTONE");
    ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "grid"}}))["class"], "PATTERN");
    auto saved = c.call({{"cmd", "save"}, {"id", "s"}});
    ASSERT_TRUE(saved);
    ASSERT_EQ((*saved)["class"], "SAVE") << saved->dump();
    // Changed after the save: must not survive.
    ASSERT_EQ((*c.call({{"cmd", "pattern"}, {"name", "white"}}))["class"], "PATTERN");
    d.signal(SIGKILL);
    ASSERT_EQ(d.wait(), -SIGKILL);
  }
  DaemonProcess again(dir);  // the killed daemon left a stale socket behind
  ASSERT_TRUE(again.started()) << again.log();
  Connection c(again.socketPath());
  auto k = c.call({{"cmd", "keystone"}});
  ASSERT_TRUE(k);
  EXPECT_EQ((*k)["corners"], kCorners);
  EXPECT_EQ((*c.call({{"cmd", "pattern"}}))["pattern"], "grid");
  EXPECT_NE(again.log().find("replacing stale control socket"), std::string::npos);
}

TEST(Lifecycle, CorruptSettingsAreReportedAndBackupUsed) {
  TempDir dir;
  {
    DaemonProcess d(dir);
    ASSERT_TRUE(d.started());
    Connection c(d.socketPath());
    ASSERT_TRUE(c.call({{"cmd", "pattern"}, {"name", "crosshair"}}));
    ASSERT_EQ((*c.call({{"cmd", "save"}}))["class"], "SAVE");
    ASSERT_TRUE(c.call({{"cmd", "pattern"}, {"name", "grid"}}));
    ASSERT_EQ((*c.call({{"cmd", "save"}}))["class"], "SAVE");
    d.signal(SIGTERM);
    ASSERT_EQ(d.wait(), 0);
    EXPECT_FALSE(std::filesystem::exists(d.socketPath()));  // removed on clean exit
  }
  std::ofstream(dir.file("state/settings.json"), std::ios::trunc) << "{\"schema\":1,\"pattern\":";
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started()) << d.log();
  Connection c(d.socketPath());
  auto s = c.call({{"cmd", "status"}});
  ASSERT_TRUE(s);
  EXPECT_EQ((*s)["pattern"], "crosshair");  // the previous save
  ASSERT_EQ((*s)["warnings"].size(), 1u);
  EXPECT_NE((*s)["warnings"][0].get<std::string>().find("settings.json is corrupt"),
            std::string::npos);
}

TEST(Lifecycle, SecondDaemonOnALiveSocketRefusesToStart) {
  TempDir dir;
  DaemonProcess first(dir);
  ASSERT_TRUE(first.started());
  DaemonProcess second(dir, DaemonProcess::Launch{{}, {}, -1, false});
  EXPECT_EQ(second.wait(), 1);
  EXPECT_NE(second.log().find("another process is listening"), std::string::npos) << second.log();
  Connection c(first.socketPath());
  EXPECT_TRUE(c.ok());  // the first one is untouched
}

TEST(Lifecycle, SocketModeIs0660) {
  TempDir dir;
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started());
  struct stat st {};
  ASSERT_EQ(::stat(d.socketPath().c_str(), &st), 0);
  EXPECT_TRUE(S_ISSOCK(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0660u);
}

TEST(Lifecycle, UsesTheSocketPassedBySystemd) {
  TempDir dir;
  const std::string path = dir.file("activated.sock");
  const int fd = boundUnixSocket(path, true);
  ASSERT_GE(fd, 0);
  DaemonProcess d(dir, DaemonProcess::Launch{{}, {}, fd, false});
  ::close(fd);
  ASSERT_TRUE(eventually([&] { return Connection(path).ok(); })) << d.log();
  Connection c(path);
  EXPECT_EQ((*c.call({{"cmd", "version"}}))["class"], "VERSION");
  EXPECT_FALSE(std::filesystem::exists(d.socketPath()));  // did not bind its own
  EXPECT_NE(d.log().find("socket passed by systemd"), std::string::npos);
}

TEST(Lifecycle, NotifiesReadyStatusAndWatchdog) {
  TempDir dir;
  const std::string path = dir.file("notify.sock");
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  std::string env_sock = "NOTIFY_SOCKET=" + path;
  // WATCHDOG_PID must name the daemon: leave it out so that any pid accepts.
  DaemonProcess d(dir, DaemonProcess::Launch{{}, {env_sock, "WATCHDOG_USEC=200000"}, -1, true});
  ASSERT_TRUE(d.started());
  std::string all;
  ASSERT_TRUE(eventually([&] {
    char buf[4096];
    const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n > 0) all.append(buf, static_cast<size_t>(n)).append("\n");
    return all.find("READY=1") != std::string::npos && all.find("WATCHDOG=1") != std::string::npos;
  }));
  EXPECT_NE(all.find("STATUS=ready"), std::string::npos) << all;
  d.signal(SIGTERM);
  EXPECT_EQ(d.wait(), 0);
  ASSERT_TRUE(eventually([&] {
    char buf[4096];
    const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n > 0) all.append(buf, static_cast<size_t>(n));
    return all.find("STOPPING=1") != std::string::npos;
  }));
  ::close(fd);
}

TEST(Lifecycle, PeerThatIsNeitherRootNorProcamIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to connect as another user";
  TempDir dir;
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started());
  // Let anybody reach the socket so that the credential check is what decides.
  ASSERT_EQ(::chmod(d.socketPath().c_str(), 0666), 0);
  ASSERT_EQ(::chmod(dir.file("run").c_str(), 0755), 0);
  ASSERT_EQ(::chmod(dir.path().c_str(), 0755), 0);
  int pipefd[2];
  ASSERT_EQ(::pipe(pipefd), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipefd[0]);
    if (::setgroups(0, nullptr) != 0 || ::setgid(65534) != 0 || ::setuid(65534) != 0) std::_Exit(3);
    Connection c(d.socketPath());  // the first line is the refusal, not a banner
    std::string line = c.ok() ? c.banner().dump() : "none";
    ssize_t rc = ::write(pipefd[1], line.data(), line.size());
    (void)rc;
    std::_Exit(c.closedByPeer(2s) ? 0 : 4);
  }
  ::close(pipefd[1]);
  std::string got;
  char buf[512];
  ssize_t n;
  while ((n = ::read(pipefd[0], buf, sizeof buf)) > 0) got.append(buf, static_cast<size_t>(n));
  ::close(pipefd[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const json refusal = json::parse(got, nullptr, false);
  EXPECT_EQ(refusal["class"], "ERROR") << got;
  EXPECT_EQ(refusal["code"], "forbidden") << got;
  EXPECT_NE(d.log().find("refused client"), std::string::npos);
}

TEST(Lifecycle, BadConfigStopsStartupNamingKeyAndLine) {
  TempDir dir;
  dir.write("bad.toml", "[policy]\n\nauto_keystone = 1\n");
  DaemonProcess d(dir, DaemonProcess::Launch{{"--config", dir.file("bad.toml")}, {}, -1, false});
  EXPECT_EQ(d.wait(), 1);
  EXPECT_NE(d.log().find("bad.toml:3: policy.auto_keystone: expected true or false"),
            std::string::npos)
      << d.log();
}

}  // namespace
}  // namespace procam::itest
