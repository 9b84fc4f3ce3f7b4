#pragma once
// Child processes for the demo: run a program to completion with its output, or
// start one with its stdout on a pipe and read it line by line.
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace procam::demo {

struct Finished {
  int status = -1;  // exit status, or -signal
  std::string out;
};
Finished runToEnd(const std::vector<std::string>& argv);

class Child {
 public:
  // stdout on a pipe (or into `log_file` when given); stderr into `log_file`
  // or inherited.
  static std::optional<Child> start(const std::vector<std::string>& argv,
                                    const std::string& log_file = "", bool pipe_stdout = true);
  Child(Child&& o) noexcept;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child();  // SIGTERM and reap when still running

  pid_t pid() const { return pid_; }
  // The next line of stdout; nullopt on timeout or end of output.
  std::optional<std::string> readLine(std::chrono::milliseconds timeout);
  // SIGTERM, then the exit status (or -signal).
  int stop();

 private:
  Child(pid_t pid, int out_fd) : pid_(pid), out_(out_fd) {}
  pid_t pid_ = -1;
  int out_ = -1;
  std::string buffer_;
  bool eof_ = false;
};

}  // namespace procam::demo
