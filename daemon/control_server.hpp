#pragma once
// Serves the control socket: accepts clients (peer checked with SO_PEERCRED),
// sends the VERSION banner, frames requests, and queues replies per client.
// A client whose output queue exceeds its bound, or that stops reading for
// longer than the stall timeout, is dropped with a logged reason: no client
// can stall the loop or the others.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/unique_fd.hpp"
#include "event_loop.hpp"
#include "log.hpp"
#include "protocol.hpp"

namespace procam::daemon {

using ClientId = uint64_t;

struct PeerCred {
  pid_t pid = 0;
  uid_t uid = 0;
  gid_t gid = 0;
};

struct ServerOptions {
  std::string release;
  size_t max_clients = 128;
  size_t queue_limit_bytes = 1024 * 1024;
  std::chrono::milliseconds stall_timeout{10000};
  gid_t group = static_cast<gid_t>(-1);  // the procam group; -1 when it does not exist
  // Descriptors kept from clients under RLIMIT_NOFILE (at most a quarter of it): a device
  // reopened after an unplug, a content stream or a timer must not fail because clients
  // hold them all.
  size_t descriptor_headroom = 32;
};

struct ServerStats {
  uint64_t accepted = 0;
  uint64_t refused = 0;  // peer not allowed, or too many clients
  uint64_t dropped = 0;  // slow or misbehaving clients
  uint64_t requests = 0;
  uint64_t malformed = 0;  // requests answered with a protocol-level ERROR
};

class ControlServer {
 public:
  using RequestHandler = std::function<void(ClientId, const proto::Request&)>;
  using DisconnectHandler = std::function<void(ClientId)>;

  ControlServer(EventLoop& loop, UniqueFd listen_fd, ServerOptions options,
                RequestHandler on_request, DisconnectHandler on_disconnect);
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;
  ~ControlServer();

  Result<void> start();
  // New options; the descriptor limit is read again too.
  void setOptions(const ServerOptions& options);

  // Queues one line for a client; false when the client is gone or was just
  // dropped for exceeding its queue bound.
  bool send(ClientId client, std::string line);
  // While held, a client that half-closed its side stays connected (an
  // asynchronous reply is on its way).
  void hold(ClientId client);
  void release(ClientId client);
  // Drops clients that stopped reading; call periodically.
  void checkStalls();

  // Descriptors a client passed (SCM_RIGHTS) with the request being handled, at
  // most kMaxPassedFds per request. Only a handler that wants them takes them;
  // the server closes every one not taken once the handler returns.
  static constexpr size_t kMaxPassedFds = 4;
  std::vector<UniqueFd> takePassedFds(ClientId client);

  bool connected(ClientId client) const;
  std::optional<PeerCred> peer(ClientId client) const;
  size_t clientCount() const { return clients_.size(); }
  const ServerStats& stats() const { return stats_; }

 private:
  struct Client {
    UniqueFd fd;
    PeerCred cred;
    proto::LineFramer framer;
    std::deque<std::string> out;
    size_t out_offset = 0;  // bytes of out.front() already written
    size_t queued = 0;
    std::chrono::steady_clock::time_point last_progress;
    bool want_write = false;
    bool read_closed = false;
    bool reading_paused = false;  // replies over half the queue bound wait to be read
    bool closing = false;
    int holds = 0;
    std::vector<UniqueFd> passed_fds;  // for the next request that completes
  };

  void readDescriptorLimit();  // RLIMIT_NOFILE's soft limit into descriptor_limit_
  void onAccept();
  // accept() failed for want of descriptors: refuse one client with `busy`.
  void refuseWithoutDescriptors();
  void pauseAccepting();  // 100 ms without watching the listening socket
  void resumeAccepting();
  void onClientEvent(ClientId id, uint32_t events);
  void readFrom(ClientId id, Client& c);
  // Handles the framed requests while the client's output queue allows; false
  // when the client or the server went away meanwhile.
  bool dispatch(ClientId id, Client& c);
  void resumeReading(ClientId id);
  uint32_t eventsFor(const Client& c) const;
  // recv() that also collects SCM_RIGHTS descriptors into c.passed_fds.
  ssize_t receive(Client& c, char* buf, size_t size);
  void flush(ClientId id, Client& c);
  void drop(ClientId id, Client& c, const std::string& reason);
  void maybeFinish(ClientId id, Client& c);
  void reap();
  bool peerAllowed(int fd, const PeerCred& cred) const;
  std::string describe(const Client& c) const;

  EventLoop& loop_;
  UniqueFd listen_fd_;
  UniqueFd reserve_fd_;          // /dev/null, closed when accept() finds no descriptor free
  size_t descriptor_limit_ = 0;  // RLIMIT_NOFILE's soft limit; 0: none
  bool accept_paused_ = false;
  // Warnings that a storm of clients could repeat without end: a few per 10 s, one
  // throttle per kind of warning (its count of held-back lines is about that kind).
  LogThrottle accept_log_;
  LogThrottle refuse_log_{std::chrono::seconds(10), 5};  // peer not allowed
  LogThrottle busy_log_{std::chrono::seconds(10), 5};    // too many clients
  LogThrottle watch_log_{std::chrono::seconds(10), 5};   // a client not set up
  LogThrottle fds_log_{std::chrono::seconds(10), 5};     // too many passed descriptors
  ServerOptions options_;
  RequestHandler on_request_;
  DisconnectHandler on_disconnect_;
  std::map<ClientId, std::unique_ptr<Client>> clients_;
  std::vector<ClientId> to_reap_;
  bool reap_scheduled_ = false;
  ClientId next_id_ = 1;
  ServerStats stats_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace procam::daemon
