#include "daemon_harness.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace procam::itest {

namespace fs = std::filesystem;

TempDir::TempDir() {
  std::string tmpl = (fs::temp_directory_path() / "procamd-test-XXXXXX").string();
  if (::mkdtemp(tmpl.data())) path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ec;
  if (!path_.empty()) fs::remove_all(path_, ec);
}

void TempDir::write(const std::string& name, const std::string& text) const {
  std::ofstream(file(name), std::ios::binary) << text;
}

std::string contentFile(const TempDir& root, const std::string& name) {
  std::filesystem::create_directories(root.file("state/content"));
  return root.file("state/content/" + name);
}

json ctlJson(const DaemonProcess& d, const std::vector<std::string>& args, int& status) {
  std::vector<std::string> argv = {PROCAMCTL_BIN, "--socket", d.socketPath(), "--json"};
  argv.insert(argv.end(), args.begin(), args.end());
  const RunResult r = runProgram(argv);
  status = r.status;
  std::string last;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) last = line;
  }
  return json::parse(last, nullptr, false);
}

void writeContent(const TempDir& root, const std::string& name, const std::string& text) {
  std::ofstream(contentFile(root, name), std::ios::binary) << text;
}

DaemonProcess::DaemonProcess(const TempDir& root, Launch launch)
    : run_dir_(root.file("run")), log_path_(root.file("daemon.log")) {
  std::vector<std::string> args = {PROCAMD_BIN, "--runtime-dir", run_dir_, "--state-dir",
                                   root.file("state")};
  args.insert(args.end(), launch.args.begin(), launch.args.end());
  pid_ = ::fork();
  if (pid_ == 0) {
    const int log = ::open(log_path_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    ::dup2(log, STDERR_FILENO);
    ::dup2(log, STDOUT_FILENO);
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("LISTEN_FDS");
    for (const auto& e : launch.env) ::putenv(const_cast<char*>(e.c_str()));
    if (launch.max_fds > 0) {
      const rlimit limit{rlim_t(launch.max_fds), rlim_t(launch.max_fds)};
      ::setrlimit(RLIMIT_NOFILE, &limit);
    }
    if (launch.listen_fd >= 0) {
      ::dup2(launch.listen_fd, 3);
      ::setenv("LISTEN_FDS", "1", 1);
      ::setenv("LISTEN_PID", std::to_string(::getpid()).c_str(), 1);
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    std::_Exit(127);
  }
  if (pid_ < 0) return;
  if (!launch.wait_for_socket) {
    started_ = true;
    return;
  }
  started_ = eventually([&] {
    if (reaped_) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      return false;
    }
    Connection c(socketPath());
    return c.ok();
  });
}

DaemonProcess::~DaemonProcess() {
  if (pid_ > 0 && !reaped_) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
}

std::string DaemonProcess::log() const {
  std::ifstream in(log_path_);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void DaemonProcess::signal(int signo) {
  if (pid_ > 0 && !reaped_) ::kill(pid_, signo);
}

std::optional<int> DaemonProcess::wait(std::chrono::milliseconds timeout) {
  std::optional<int> result;
  eventually(
      [&] {
        int status = 0;
        if (reaped_ || ::waitpid(pid_, &status, WNOHANG) != pid_) return false;
        reaped_ = true;
        result = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
        return true;
      },
      timeout);
  return result;
}

Connection::Connection(const std::string& socket_path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, socket_path.c_str(), sizeof addr.sun_path - 1);
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) return;
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd_);
    fd_ = -1;
    return;
  }
  auto banner = next(2s);
  if (!banner) {
    ::close(fd_);
    fd_ = -1;
    return;
  }
  banner_ = *banner;
}

Connection::~Connection() {
  if (fd_ >= 0) ::close(fd_);
}

Connection::Connection(Connection&& o) noexcept
    : fd_(std::exchange(o.fd_, -1)), buf_(std::move(o.buf_)), banner_(std::move(o.banner_)) {}

bool Connection::sendRaw(const std::string& bytes) {
  size_t off = 0;
  while (off < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + off, bytes.size() - off, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    off += static_cast<size_t>(n);
  }
  return true;
}

std::optional<json> Connection::next(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const size_t nl = buf_.find('\n');
    if (nl != std::string::npos) {
      json j = json::parse(buf_.substr(0, nl), nullptr, false);
      buf_.erase(0, nl + 1);
      if (j.is_discarded()) return std::nullopt;
      return j;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char chunk[65536];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n <= 0) return std::nullopt;
    buf_.append(chunk, static_cast<size_t>(n));
  }
}

std::optional<json> Connection::call(const json& request, std::chrono::milliseconds timeout) {
  if (!send(request)) return std::nullopt;
  for (;;) {
    auto msg = next(timeout);
    if (!msg || msg->value("class", "") != "EVENT") return msg;
  }
}

bool Connection::closedByPeer(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    char chunk[65536];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n == 0 || (n < 0 && errno == ECONNRESET)) return true;
  }
  return false;
}

RunResult runProgram(const std::vector<std::string>& argv, const std::string& stdin_text) {
  int in[2], out[2], err[2];
  if (::pipe(in) || ::pipe(out) || ::pipe(err)) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(in[0], 0);
    ::dup2(out[1], 1);
    ::dup2(err[1], 2);
    for (int fd : {in[0], in[1], out[0], out[1], err[0], err[1]}) ::close(fd);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    std::_Exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  ::close(err[1]);
  if (!stdin_text.empty()) {
    ssize_t rc = ::write(in[1], stdin_text.data(), stdin_text.size());
    (void)rc;
  }
  ::close(in[1]);
  RunResult r;
  auto drain = [](int fd, std::string& into) {
    char buf[4096];
    ssize_t n;
    while ((n = ::read(fd, buf, sizeof buf)) > 0) into.append(buf, static_cast<size_t>(n));
    ::close(fd);
  };
  std::thread t([&] { drain(err[0], r.err); });
  drain(out[0], r.out);
  t.join();
  int status = 0;
  ::waitpid(pid, &status, 0);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::optional<json> finalReply(Connection& c, int id, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout * kSlowdown;
  while (std::chrono::steady_clock::now() < deadline) {
    auto msg = c.next(std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now()));
    if (!msg) return std::nullopt;
    if ((*msg)["class"] != "EVENT" && (*msg)["id"] == id && (*msg)["state"] != "started") {
      return msg;
    }
  }
  return std::nullopt;
}

}  // namespace procam::itest
