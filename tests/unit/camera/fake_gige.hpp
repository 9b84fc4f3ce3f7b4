#pragma once
// Aravis' fake GigE Vision camera (arv-fake-gv-camera-0.8, package aravis-tools) as a
// child process on loopback, for the tests that run the aravis driver live
// (HARDWARE-TESTING.md). Open it by kLoopback: by its discovered name the stream binds
// to another interface and every frame times out.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

extern char** environ;

namespace procam::test {

inline constexpr const char* kFakeBinary = "arv-fake-gv-camera-0.8";
inline constexpr const char* kLoopback = "127.0.0.1";

// The executable's path, or empty when it is not on PATH.
inline std::string findOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const auto p = std::filesystem::path(dir) / name;
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return {};
}

// One fake camera server; the GigE server's frame counter persists across clients, so
// each test starts its own. Killed (SIGKILL, as a camera losing power) and reaped when
// destroyed.
class FakeGigE {
 public:
  explicit FakeGigE(const std::string& binary) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    const char* argv[] = {binary.c_str(), "-i", kLoopback, nullptr};
    if (posix_spawn(&pid_, binary.c_str(), &actions, nullptr, const_cast<char**>(argv), environ) !=
        0)
      pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~FakeGigE() { kill(); }
  FakeGigE(const FakeGigE&) = delete;
  FakeGigE& operator=(const FakeGigE&) = delete;
  bool running() const { return pid_ > 0; }
  void kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};

}  // namespace procam::test
