#include "client.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace procam::ctl {

using nlohmann::json;

tl::expected<Client, ClientError> Client::connect(const std::string& path,
                                                  std::chrono::milliseconds timeout) {
  Client c;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof addr.sun_path) {
    return tl::unexpected(ClientError{kExitUsage, "socket path too long: " + path});
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  c.fd_.reset(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!c.fd_.valid()) return tl::unexpected(ClientError{kExitConnect, std::strerror(errno)});
  if (::connect(c.fd_.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int e = errno;
    std::string hint = e == EACCES ? " (are you root or in the procam group?)"
                       : (e == ENOENT || e == ECONNREFUSED) ? " (is procamd running?)"
                                                            : "";
    return tl::unexpected(
        ClientError{kExitConnect, "cannot connect to " + path + ": " + std::strerror(e) + hint});
  }
  auto banner = c.next(timeout);
  if (!banner) return tl::unexpected(banner.error());
  if (banner->value("class", "") == "ERROR") {
    const std::string code = banner->value("code", "");
    return tl::unexpected(ClientError{
        kExitConnect, "procamd refused the connection: " + banner->value("message", code)});
  }
  if (banner->value("class", "") != "VERSION" || !(*banner)["proto_major"].is_number_integer()) {
    return tl::unexpected(ClientError{kExitProtocol, "no VERSION banner from " + path});
  }
  if ((*banner)["proto_major"].get<int>() != daemon::proto::kMajor) {
    return tl::unexpected(ClientError{
        kExitProtocol,
        "procamd speaks protocol " + std::to_string((*banner)["proto_major"].get<int>()) +
            ".x, this procamctl speaks " + std::to_string(daemon::proto::kMajor) + ".x"});
  }
  c.banner_ = *banner;
  return c;
}

tl::expected<void, ClientError> Client::send(const json& request) {
  const std::string line = request.dump() + "\n";
  size_t off = 0;
  while (off < line.size()) {
    const ssize_t n = ::send(fd_.get(), line.data() + off, line.size() - off, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return tl::unexpected(
          ClientError{kExitProtocol, std::string("send: ") + std::strerror(errno)});
    }
    off += static_cast<size_t>(n);
  }
  return {};
}

tl::expected<json, ClientError> Client::next(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    daemon::proto::LineFramer::Item item;
    while (framer_.next(item)) {
      if (item.oversized) continue;
      json j = json::parse(item.line, nullptr, false);
      if (j.is_discarded() || !j.is_object()) {
        return tl::unexpected(
            ClientError{kExitProtocol, "procamd sent a line that is not a JSON object"});
      }
      return j;
    }
    int wait_ms = -1;
    if (timeout.count() >= 0) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) {
        return tl::unexpected(ClientError{kExitProtocol, "timed out waiting for procamd"});
      }
      wait_ms = static_cast<int>(left.count());
    }
    pollfd p{fd_.get(), POLLIN, 0};
    const int r = ::poll(&p, 1, wait_ms);
    if (r < 0 && errno == EINTR) continue;
    if (r == 0) continue;  // re-checks the deadline
    char buf[65536];
    const ssize_t n = ::recv(fd_.get(), buf, sizeof buf, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      return tl::unexpected(ClientError{kExitProtocol, "procamd closed the connection"});
    }
    framer_.feed(std::string_view(buf, static_cast<size_t>(n)));
  }
}

tl::expected<json, ClientError> Client::call(json request, std::chrono::milliseconds timeout,
                                             const std::function<void(const json&)>& on_event) {
  const int id = next_id_++;
  request["id"] = id;
  if (auto ok = send(request); !ok) return tl::unexpected(ok.error());
  for (;;) {
    auto msg = next(timeout);
    if (!msg) return msg;
    if (msg->value("class", "") == "EVENT") {
      if (on_event) on_event(*msg);
      continue;
    }
    auto it = msg->find("id");
    if (it != msg->end() && it->is_number_integer() && it->get<int>() == id) return msg;
  }
}

}  // namespace procam::ctl
