// procamctl against the real daemon: readable output, --json, exit codes.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "daemon_harness.hpp"

namespace procam::itest {
namespace {

RunResult ctl(const DaemonProcess& d, std::vector<std::string> args) {
  std::vector<std::string> argv = {PROCAMCTL_BIN, "--socket", d.socketPath()};
  argv.insert(argv.end(), args.begin(), args.end());
  return runProgram(argv);
}

TEST(Procamctl, ReadableStatusAndJsonOutput) {
  TempDir dir;
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started());
  auto status = ctl(d, {"status"});
  EXPECT_EQ(status.status, 0) << status.err;
  EXPECT_NE(status.out.find("pattern:       off"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("auto_keystone, calibrate, render"), std::string::npos) << status.out;

  auto js = ctl(d, {"--json", "pattern", "grid"});
  EXPECT_EQ(js.status, 0);
  const json reply = json::parse(js.out, nullptr, false);
  ASSERT_FALSE(reply.is_discarded()) << js.out;
  EXPECT_EQ(reply["class"], "PATTERN");
  EXPECT_EQ(reply["pattern"], "grid");

  auto ks = ctl(d, {"keystone", "set", "10,10", "1900,20", "1890,1070", "5,1060"});
  EXPECT_EQ(ks.status, 0) << ks.err;
  EXPECT_NE(ks.out.find("corners:       10,10 1900,20 1890,1070 5,1060"), std::string::npos)
      << ks.out;
  auto saved = ctl(d, {"save"});
  EXPECT_EQ(saved.status, 0);
  EXPECT_NE(saved.out.find("settings.json"), std::string::npos);
}

TEST(Procamctl, ExitCodes) {
  TempDir dir;
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started());
  EXPECT_EQ(ctl(d, {"version"}).status, 0);
  auto bad = ctl(d, {"keystone", "set", "0,0", "0,1079", "1919,1079", "1919,0"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("error (bad-argument)"), std::string::npos) << bad.err;
  EXPECT_EQ(ctl(d, {"frobnicate"}).status, 2);
  EXPECT_EQ(ctl(d, {"keystone", "set", "1,2"}).status, 2);
  EXPECT_EQ(ctl(d, {"calibrate"}).status, 5);
  EXPECT_EQ(ctl(d, {"keystone", "auto", "on"}).status, 5);
  auto none = runProgram({PROCAMCTL_BIN, "--socket", dir.file("nothing.sock"), "status"});
  EXPECT_EQ(none.status, 3);
  EXPECT_NE(none.err.find("is procamd running?"), std::string::npos) << none.err;
}

TEST(Procamctl, WatchStreamsEvents) {
  TempDir dir;
  DaemonProcess d(dir);
  ASSERT_TRUE(d.started());
  // procamctl watch runs until killed: read its first lines through a pipe.
  int out[2];
  ASSERT_EQ(::pipe(out), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(out[1], 1);
    ::close(out[0]);
    ::execl(PROCAMCTL_BIN, PROCAMCTL_BIN, "--socket", d.socketPath().c_str(), "--json", "watch",
            static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  ::close(out[1]);
  std::string got;
  auto readUntil = [&](const std::string& needle) {
    return eventually([&] {
      pollfd p{out[0], POLLIN, 0};
      if (::poll(&p, 1, 20) > 0) {
        char buf[4096];
        const ssize_t n = ::read(out[0], buf, sizeof buf);
        if (n > 0) got.append(buf, static_cast<size_t>(n));
      }
      return got.find(needle) != std::string::npos;
    });
  };
  ASSERT_TRUE(readUntil("\"class\":\"WATCH\"")) << got;
  EXPECT_EQ(ctl(d, {"pattern", "white"}).status, 0);
  EXPECT_TRUE(readUntil("\"event\":\"pattern\"")) << got;
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ::close(out[0]);
}

}  // namespace
}  // namespace procam::itest
