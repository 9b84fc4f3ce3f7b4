#include "control_server.hpp"

#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "log.hpp"

namespace procam::daemon {

namespace {
constexpr size_t kReadChunk = 64 * 1024;

// A warning a storm of clients could repeat thousands of times a second.
void throttledWarning(LogThrottle& throttle, const std::string& message) {
  if (auto line = throttle.pass(message)) logWarning(*line);
}

constexpr size_t kReadBudgetPerWakeup = 4 * kReadChunk;  // fairness between clients
}  // namespace

ControlServer::ControlServer(EventLoop& loop, UniqueFd listen_fd, ServerOptions options,
                             RequestHandler on_request, DisconnectHandler on_disconnect)
    : loop_(loop),
      listen_fd_(std::move(listen_fd)),
      options_(std::move(options)),
      on_request_(std::move(on_request)),
      on_disconnect_(std::move(on_disconnect)) {}

ControlServer::~ControlServer() {
  *alive_ = false;
  for (auto& [id, c] : clients_) {
    if (!c->closing) loop_.remove(c->fd.get());
  }
  if (listen_fd_.valid()) loop_.remove(listen_fd_.get());
}

void ControlServer::refuseWithoutDescriptors() {
  // The reserve descriptor makes room for one accept, so that the client in the
  // backlog hears why instead of waiting; then it is taken back.
  if (reserve_fd_.valid()) {
    reserve_fd_.reset();
    UniqueFd fd(::accept4(listen_fd_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (fd.valid()) {
      const std::string line =
          proto::error(nullptr, proto::code::kBusy, "procamd is out of file descriptors");
      ssize_t rc = ::send(fd.get(), line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      (void)rc;
      ++stats_.refused;
    }
    fd.reset();
    reserve_fd_.reset(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  }
  // Without a reserve (or with clients still queued behind it) the listening
  // socket would stay readable and the loop spin: stop watching it a while.
  if (!reserve_fd_.valid()) {
    reserve_fd_.reset(::open("/dev/null", O_RDONLY | O_CLOEXEC));
    pauseAccepting();
  }
}

void ControlServer::pauseAccepting() {
  if (accept_paused_) return;
  accept_paused_ = true;
  loop_.remove(listen_fd_.get());
  // A timer takes a descriptor too: without one, checkStalls() (every second)
  // resumes instead.
  std::weak_ptr<bool> alive = alive_;
  (void)loop_.addTimer(std::chrono::milliseconds(100), false, [this, alive] {
    if (!alive.expired()) resumeAccepting();
  });
}

void ControlServer::resumeAccepting() {
  if (!accept_paused_) return;
  if (auto ok = loop_.add(listen_fd_.get(), EPOLLIN, [this](uint32_t) { onAccept(); }); !ok) {
    if (auto line = accept_log_.pass("control socket: " + ok.error().message)) logError(*line);
    return;  // tried again on the next checkStalls()
  }
  accept_paused_ = false;
}

void ControlServer::readDescriptorLimit() {
  rlimit limit{};
  descriptor_limit_ = ::getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY
                          ? static_cast<size_t>(limit.rlim_cur)
                          : 0;
}

void ControlServer::setOptions(const ServerOptions& options) {
  options_ = options;
  readDescriptorLimit();
}

Result<void> ControlServer::start() {
  reserve_fd_.reset(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  readDescriptorLimit();
  return loop_.add(listen_fd_.get(), EPOLLIN, [this](uint32_t) { onAccept(); });
}

bool ControlServer::peerAllowed(int fd, const PeerCred& cred) const {
  if (cred.uid == 0 || cred.uid == ::geteuid()) return true;
  if (options_.group == static_cast<gid_t>(-1)) return false;
  if (cred.gid == options_.group) return true;
  // Supplementary groups of the peer, as the kernel recorded them at connect().
  gid_t groups[256];
  socklen_t len = sizeof groups;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups, &len) != 0) return false;
  const size_t n = len / sizeof(gid_t);
  return std::find(groups, groups + n, options_.group) != groups + n;
}

std::string ControlServer::describe(const Client& c) const {
  return "client pid " + std::to_string(c.cred.pid) + " uid " + std::to_string(c.cred.uid);
}

void ControlServer::onAccept() {
  for (int i = 0; i < 64; ++i) {
    UniqueFd fd(::accept4(listen_fd_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!fd.valid()) {
      const int err = errno;
      if (err == EAGAIN || err == EWOULDBLOCK) return;
      // One connection's failure (it went away before being accepted): the next.
      if (err == EINTR || err == ECONNABORTED || err == EPROTO || err == EPERM) continue;
      if (auto line = accept_log_.pass(std::string("accept: ") + std::strerror(err))) {
        logWarning(*line);
      }
      if (err == EMFILE || err == ENFILE) {
        refuseWithoutDescriptors();
        if (accept_paused_) return;
        continue;
      }
      // Anything else (ENOMEM, ENOBUFS...): give the system a moment, do not spin.
      pauseAccepting();
      return;
    }
    PeerCred cred;
    ucred uc{};
    socklen_t len = sizeof uc;
    if (::getsockopt(fd.get(), SOL_SOCKET, SO_PEERCRED, &uc, &len) != 0) {
      throttledWarning(watch_log_, std::string("SO_PEERCRED: ") + std::strerror(errno));
      ++stats_.refused;
      continue;
    }
    cred = {uc.pid, uc.uid, uc.gid};
    auto refuse = [&](const char* code, const std::string& message) {
      const std::string line = proto::error(nullptr, code, message);
      ssize_t rc = ::send(fd.get(), line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      (void)rc;
      ++stats_.refused;
    };
    if (!peerAllowed(fd.get(), cred)) {
      throttledWarning(refuse_log_, "refused client pid " + std::to_string(cred.pid) + " uid " +
                                        std::to_string(cred.uid) +
                                        ": not root and not in the procam group");
      refuse(proto::code::kForbidden, "not root and not in the procam group");
      continue;
    }
    if (clients_.size() >= options_.max_clients) {
      throttledWarning(busy_log_, "refused client pid " + std::to_string(cred.pid) + ": " +
                                      std::to_string(clients_.size()) +
                                      " clients connected (daemon.max_clients)");
      refuse(proto::code::kBusy, "too many clients");
      continue;
    }
    // Descriptors are given lowest first, so every one below this client's is in use:
    // fewer than the headroom would be left for the daemon's own. At most a quarter of a
    // small limit, so that clients still get in under it.
    const size_t headroom = std::min(options_.descriptor_headroom, descriptor_limit_ / 4);
    if (descriptor_limit_ > 0 && static_cast<size_t>(fd.get()) + headroom >= descriptor_limit_) {
      throttledWarning(busy_log_, "refused client pid " + std::to_string(cred.pid) + ": " +
                                      std::to_string(clients_.size()) +
                                      " clients connected, the last " + std::to_string(headroom) +
                                      " of " + std::to_string(descriptor_limit_) +
                                      " file descriptors are kept for devices");
      refuse(proto::code::kBusy, "too many clients for procamd's file descriptor limit");
      continue;
    }
    const ClientId id = next_id_++;
    auto c = std::make_unique<Client>();
    c->fd = std::move(fd);
    c->cred = cred;
    c->last_progress = std::chrono::steady_clock::now();
    const int cfd = c->fd.get();
    if (auto ok = loop_.add(cfd, EPOLLIN | EPOLLRDHUP,
                            [this, id](uint32_t ev) { onClientEvent(id, ev); });
        !ok) {
      throttledWarning(watch_log_, "cannot watch client: " + ok.error().message);
      continue;
    }
    Client& ref = *c;
    clients_.emplace(id, std::move(c));
    ++stats_.accepted;
    logDebug(describe(ref) + " connected (id " + std::to_string(id) + ")");
    send(id, proto::versionBanner(options_.release));
  }
}

void ControlServer::onClientEvent(ClientId id, uint32_t events) {
  auto it = clients_.find(id);
  if (it == clients_.end() || it->second->closing) return;
  Client& c = *it->second;
  if (events & EPOLLOUT) {
    flush(id, c);
    if (c.closing) return;
  }
  if (events & (EPOLLIN | EPOLLRDHUP | EPOLLHUP | EPOLLERR)) readFrom(id, c);
  if ((events & (EPOLLHUP | EPOLLERR)) && !c.closing) {
    // The peer is gone in both directions: nothing queued can be delivered.
    logDebug(describe(c) + " hung up");
    c.closing = true;
    loop_.remove(c.fd.get());
    to_reap_.push_back(id);
    reap();
  }
}

uint32_t ControlServer::eventsFor(const Client& c) const {
  const bool reading = !c.read_closed && !c.reading_paused;
  return (reading ? uint32_t{EPOLLIN | EPOLLRDHUP} : 0u) | (c.want_write ? uint32_t{EPOLLOUT} : 0u);
}

bool ControlServer::dispatch(ClientId id, Client& c) {
  proto::LineFramer::Item item;
  for (;;) {
    // A client whose replies pile up unread is not read further until they drain:
    // its requests wait in the socket (back-pressure) instead of filling memory.
    if (c.queued > options_.queue_limit_bytes / 2) {
      if (!c.reading_paused) {
        c.reading_paused = true;
        loop_.modify(c.fd.get(), eventsFor(c));
      }
      return true;
    }
    if (!c.framer.next(item)) return true;
    if (item.oversized) {
      ++stats_.malformed;
      send(id, proto::error(nullptr, proto::code::kTooLarge,
                            "request longer than " + std::to_string(proto::kMaxRequestBytes) +
                                " bytes; skipped up to its newline"));
    } else if (item.line.find_first_not_of(" \t") == std::string::npos) {
      c.passed_fds.clear();
      continue;  // blank lines are ignored
    } else {
      auto req = proto::parseRequest(item.line);
      ++stats_.requests;
      if (!req) {
        ++stats_.malformed;
        send(id, proto::error(req.error().id, req.error().code, req.error().message));
      } else {
        std::weak_ptr<bool> alive = alive_;
        on_request_(id, *req);
        if (alive.expired()) return false;  // the server itself went away (shutdown)
      }
    }
    if (!connected(id)) return false;  // dropped while handling (queue overflow)
    c.passed_fds.clear();              // descriptors the handler did not take
  }
}

void ControlServer::resumeReading(ClientId id) {
  auto it = clients_.find(id);
  if (it == clients_.end() || it->second->closing) return;
  Client& c = *it->second;
  if (!c.reading_paused || c.queued > options_.queue_limit_bytes / 4) return;
  c.reading_paused = false;
  loop_.modify(c.fd.get(), eventsFor(c));
  readFrom(id, c);  // the requests already framed first
}

void ControlServer::readFrom(ClientId id, Client& c) {
  if (!dispatch(id, c)) return;
  char buf[kReadChunk];
  size_t budget = kReadBudgetPerWakeup;
  while (budget > 0 && !c.read_closed && !c.reading_paused) {
    const ssize_t n = receive(c, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      drop(id, c, std::string("read error: ") + std::strerror(errno));
      return;
    }
    if (n == 0) {
      c.read_closed = true;
      break;
    }
    budget -= std::min(budget, static_cast<size_t>(n));
    c.framer.feed(std::string_view(buf, static_cast<size_t>(n)));
    if (!dispatch(id, c)) return;
  }
  if (c.read_closed) {
    loop_.modify(c.fd.get(), eventsFor(c));
    maybeFinish(id, c);
  }
}

ssize_t ControlServer::receive(Client& c, char* buf, size_t size) {
  iovec iov{buf, size};
  alignas(cmsghdr) char control[CMSG_SPACE(kMaxPassedFds * sizeof(int))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = ::recvmsg(c.fd.get(), &msg, MSG_CMSG_CLOEXEC);
  if (n < 0) return n;
  for (cmsghdr* h = CMSG_FIRSTHDR(&msg); h; h = CMSG_NXTHDR(&msg, h)) {
    if (h->cmsg_level != SOL_SOCKET || h->cmsg_type != SCM_RIGHTS) continue;
    const size_t count = (h->cmsg_len - CMSG_LEN(0)) / sizeof(int);
    for (size_t i = 0; i < count; ++i) {
      int fd;
      std::memcpy(&fd, CMSG_DATA(h) + i * sizeof(int), sizeof fd);
      UniqueFd owned(fd);
      if (c.passed_fds.size() < kMaxPassedFds) c.passed_fds.push_back(std::move(owned));
    }
  }
  // The kernel closed descriptors beyond the control buffer.
  if (msg.msg_flags & MSG_CTRUNC) {
    throttledWarning(fds_log_, describe(c) + " passed more than " + std::to_string(kMaxPassedFds) +
                                   " descriptors; the rest were closed");
  }
  return n;
}

std::vector<UniqueFd> ControlServer::takePassedFds(ClientId id) {
  auto it = clients_.find(id);
  if (it == clients_.end()) return {};
  return std::exchange(it->second->passed_fds, {});
}

bool ControlServer::send(ClientId id, std::string line) {
  auto it = clients_.find(id);
  if (it == clients_.end() || it->second->closing) return false;
  Client& c = *it->second;
  c.queued += line.size();
  c.out.push_back(std::move(line));
  if (c.queued > options_.queue_limit_bytes) {
    drop(id, c,
         "output queue over " + std::to_string(options_.queue_limit_bytes / 1024) +
             " KiB (client not reading)");
    return false;
  }
  if (!c.want_write) flush(id, c);
  return !c.closing;
}

void ControlServer::flush(ClientId id, Client& c) {
  while (!c.out.empty()) {
    const std::string& front = c.out.front();
    const ssize_t n = ::send(c.fd.get(), front.data() + c.out_offset, front.size() - c.out_offset,
                             MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      drop(id, c, std::string("write error: ") + std::strerror(errno));
      return;
    }
    c.last_progress = std::chrono::steady_clock::now();
    c.out_offset += static_cast<size_t>(n);
    c.queued -= static_cast<size_t>(n);
    if (c.out_offset == front.size()) {
      c.out.pop_front();
      c.out_offset = 0;
    }
  }
  const bool want = !c.out.empty();
  if (want != c.want_write) {
    c.want_write = want;
    loop_.modify(c.fd.get(), eventsFor(c));
  }
  if (c.reading_paused && c.queued <= options_.queue_limit_bytes / 4) {
    // Read again from the loop, not from inside this send.
    std::weak_ptr<bool> alive = alive_;
    loop_.post([this, alive, id] {
      if (!alive.expired()) resumeReading(id);
    });
  }
  maybeFinish(id, c);
}

void ControlServer::maybeFinish(ClientId id, Client& c) {
  if (c.read_closed && c.out.empty() && c.holds == 0 && !c.reading_paused && !c.closing) {
    logDebug(describe(c) + " disconnected");
    c.closing = true;
    loop_.remove(c.fd.get());
    to_reap_.push_back(id);
    reap();
  }
}

void ControlServer::drop(ClientId id, Client& c, const std::string& reason) {
  if (c.closing) return;
  logWarning("dropping " + describe(c) + ": " + reason);
  ++stats_.dropped;
  c.closing = true;
  loop_.remove(c.fd.get());
  to_reap_.push_back(id);
  reap();
}

void ControlServer::reap() {
  // Deferred: callers may be iterating over clients (broadcasts, handlers).
  if (reap_scheduled_) return;
  reap_scheduled_ = true;
  std::weak_ptr<bool> alive = alive_;
  loop_.post([this, alive] {
    if (alive.expired()) return;
    reap_scheduled_ = false;
    std::vector<ClientId> ids;
    ids.swap(to_reap_);
    for (ClientId id : ids) {
      clients_.erase(id);  // closes the fd
      if (on_disconnect_) on_disconnect_(id);
    }
  });
}

void ControlServer::hold(ClientId id) {
  if (auto it = clients_.find(id); it != clients_.end()) ++it->second->holds;
}

void ControlServer::release(ClientId id) {
  auto it = clients_.find(id);
  if (it == clients_.end()) return;
  Client& c = *it->second;
  if (c.holds > 0) --c.holds;
  maybeFinish(id, c);
}

void ControlServer::checkStalls() {
  resumeAccepting();
  const auto now = std::chrono::steady_clock::now();
  for (auto& [id, c] : clients_) {
    if (c->closing || c->out.empty()) continue;
    const auto stalled = now - c->last_progress;
    if (stalled > options_.stall_timeout) {
      const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(stalled).count();
      drop(id, *c,
           "stopped reading for " + std::to_string(ms) + " ms with " + std::to_string(c->queued) +
               " bytes queued");
    }
  }
}

bool ControlServer::connected(ClientId id) const {
  auto it = clients_.find(id);
  return it != clients_.end() && !it->second->closing;
}

std::optional<PeerCred> ControlServer::peer(ClientId id) const {
  auto it = clients_.find(id);
  if (it == clients_.end()) return std::nullopt;
  return it->second->cred;
}

}  // namespace procam::daemon
