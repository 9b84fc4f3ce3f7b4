#include "demo/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <utility>

namespace procam::demo {

namespace {

[[noreturn]] void execOrDie(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  ::execv(args[0], args.data());
  ::_exit(127);
}

int statusOf(int raw) {
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -WTERMSIG(raw);
}

}  // namespace

Finished runToEnd(const std::vector<std::string>& argv) {
  auto child = Child::start(argv);
  Finished f;
  if (!child) return f;
  while (auto line = child->readLine(std::chrono::seconds(30))) f.out += *line + "\n";
  f.status = child->stop();  // the child has closed its output: it is ending or a zombie
  return f;
}

std::optional<Child> Child::start(const std::vector<std::string>& argv, const std::string& log_file,
                                  bool pipe_stdout) {
  int fds[2] = {-1, -1};
  if (pipe_stdout && ::pipe2(fds, O_CLOEXEC) != 0) return std::nullopt;
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) return std::nullopt;
  if (pid == 0) {
    // The demo's daemon and clients must not outlive the demo, however it ends (a closed
    // pipe or a signal skips the destructors that would stop them).
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);  // the parent is already gone
    if (!log_file.empty()) {
      const int log = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (log >= 0) {
        ::dup2(log, 2);
        if (!pipe_stdout) ::dup2(log, 1);
      }
    }
    if (pipe_stdout) ::dup2(fds[1], 1);
    execOrDie(argv);
  }
  if (pipe_stdout) ::close(fds[1]);
  return Child(pid, fds[0]);
}

Child::Child(Child&& o) noexcept
    : pid_(std::exchange(o.pid_, -1)),
      out_(std::exchange(o.out_, -1)),
      buffer_(std::move(o.buffer_)),
      eof_(o.eof_) {}

Child::~Child() {
  if (pid_ > 0) stop();
  if (out_ >= 0) ::close(out_);
}

std::optional<std::string> Child::readLine(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    if (auto nl = buffer_.find('\n'); nl != std::string::npos) {
      std::string line = buffer_.substr(0, nl);
      buffer_.erase(0, nl + 1);
      return line;
    }
    if (eof_ || out_ < 0) return std::nullopt;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    pollfd p{out_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char chunk[4096];
    const ssize_t n = ::read(out_, chunk, sizeof chunk);
    if (n <= 0) {
      eof_ = true;
    } else {
      buffer_.append(chunk, static_cast<size_t>(n));
    }
  }
}

int Child::stop() {
  if (pid_ <= 0) return -1;
  ::kill(pid_, SIGTERM);
  int raw = 0;
  ::waitpid(pid_, &raw, 0);
  pid_ = -1;
  return statusOf(raw);
}

}  // namespace procam::demo
