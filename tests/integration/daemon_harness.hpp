#pragma once
// Starts the real procamd binary in temporary runtime and state directories
// and talks to it only over its control socket.
#include <sys/types.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace procam::itest {

using nlohmann::json;
using namespace std::chrono_literals;

// A scratch directory removed at destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  void write(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
};

// A file in the content root of a daemon started in `root` (its state
// directory's content/, created here): where a client's content must lie.
std::string contentFile(const TempDir& root, const std::string& name);
void writeContent(const TempDir& root, const std::string& name, const std::string& text);

class DaemonProcess {
 public:
  struct Launch {
    std::vector<std::string> args;  // after the runtime/state options
    std::vector<std::string> env;   // NAME=value added to the environment
    int listen_fd = -1;             // passed as fd 3 with LISTEN_FDS=1
    bool wait_for_socket = true;
    int max_fds = 0;  // RLIMIT_NOFILE of the daemon when > 0
  };

  // `root` holds run/, state/ and daemon.log.
  DaemonProcess(const TempDir& root, Launch launch);
  DaemonProcess(const TempDir& root) : DaemonProcess(root, Launch{}) {}
  ~DaemonProcess();

  bool started() const { return started_; }
  pid_t pid() const { return pid_; }
  std::string socketPath() const { return run_dir_ + "/control.sock"; }
  std::string log() const;
  void signal(int signo);
  // Waits for exit: the exit status, or -signal when killed.
  std::optional<int> wait(std::chrono::milliseconds timeout = 5s);

 private:
  std::string run_dir_, log_path_;
  pid_t pid_ = -1;
  bool started_ = false;
  bool reaped_ = false;
};

// One control connection (blocking with timeouts).
class Connection {
 public:
  explicit Connection(const std::string& socket_path);
  ~Connection();
  Connection(Connection&& o) noexcept;
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  bool ok() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  const json& banner() const { return banner_; }
  bool sendRaw(const std::string& bytes);
  bool send(const json& request) { return sendRaw(request.dump() + "\n"); }
  // The next line as JSON; nullopt on timeout, EOF or non-JSON.
  std::optional<json> next(std::chrono::milliseconds timeout = 5s);
  // Sends and returns the next non-EVENT line.
  std::optional<json> call(const json& request, std::chrono::milliseconds timeout = 5s);
  // True when the daemon closed the connection within the timeout (reading
  // and discarding whatever comes before the end).
  bool closedByPeer(std::chrono::milliseconds timeout = 5s);

 private:
  int fd_ = -1;
  std::string buf_;
  json banner_;
};

// Runs a program, returns its exit status and output.
struct RunResult {
  int status = -1;
  std::string out, err;
};
RunResult runProgram(const std::vector<std::string>& argv, const std::string& stdin_text = "");

// `procamctl --json ARGS` against `d`: its last line (an operation prints its started
// reply and events first), and its exit status in `status`.
json ctlJson(const DaemonProcess& d, const std::vector<std::string>& args, int& status);

// The virtual cameras ray-cast every capture: about 8x slower under
// AddressSanitizer or ThreadSanitizer. Tests that wait on captures scale their
// times by this.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr int kSlowdown = 8;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr int kSlowdown = 8;
#else
inline constexpr int kSlowdown = 1;
#endif
#else
inline constexpr int kSlowdown = 1;
#endif

// Waits until `predicate` holds, polling; false on timeout.
template <class F>
bool eventually(F predicate, std::chrono::milliseconds timeout = 5s);

// The final reply to request `id` of a long operation (not its "started" reply, not an
// event); nullopt when none comes within `timeout` (times kSlowdown).
std::optional<json> finalReply(Connection& c, int id, std::chrono::milliseconds timeout);

}  // namespace procam::itest

#include "daemon_harness_inl.hpp"
