#include "control_socket.hpp"

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "log.hpp"

namespace procam::daemon {

namespace {

tl::unexpected<Error> sysError(const std::string& what) {
  return fail(ErrorCode::kIo, what + ": " + std::strerror(errno));
}

Result<sockaddr_un> unixAddress(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path) {
    return fail(ErrorCode::kInvalidInput, "control socket path '" + path +
                                              "' is empty or longer than " +
                                              std::to_string(sizeof addr.sun_path - 1) + " bytes");
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  return addr;
}

// A socket file nobody listens on is stale and may be replaced; a live one
// means another daemon owns it.
Result<void> removeIfStale(const std::string& path, const sockaddr_un& addr) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return {};
    return sysError("cannot inspect " + path);
  }
  if (!S_ISSOCK(st.st_mode)) {
    return fail(ErrorCode::kIo, path + " exists and is not a socket; not replacing it");
  }
  UniqueFd probe(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!probe.valid()) return sysError("socket");
  if (::connect(probe.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0) {
    return fail(ErrorCode::kIo, "another process is listening on " + path);
  }
  if (errno != ECONNREFUSED) return sysError("cannot probe " + path);
  logInfo("replacing stale control socket " + path);
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) return sysError("cannot remove " + path);
  return {};
}

}  // namespace

Result<ListeningSocket> openControlSocket(const std::string& path, gid_t group) {
  const int n = sd_listen_fds(1);
  if (n < 0) return fail(ErrorCode::kIo, std::string("sd_listen_fds: ") + std::strerror(-n));
  if (n > 1)
    return fail(ErrorCode::kIo, "systemd passed " + std::to_string(n) + " sockets, expected 1");
  if (n == 1) {
    const int fd = SD_LISTEN_FDS_START;
    if (sd_is_socket_unix(fd, SOCK_STREAM, 1, nullptr, 0) <= 0) {
      return fail(ErrorCode::kIo,
                  "the socket passed by systemd is not a listening Unix stream socket");
    }
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) return sysError("fcntl");
    ::fcntl(fd, F_SETFD, FD_CLOEXEC);
    return ListeningSocket{UniqueFd(fd), true, {}};
  }

  auto addr = unixAddress(path);
  if (!addr) return tl::unexpected(addr.error());
  if (auto ok = removeIfStale(path, *addr); !ok) return tl::unexpected(ok.error());
  UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return sysError("socket");
  // bind() creates the file with mode 0777 & ~umask: 0660 needs umask 0117.
  // Called before any thread starts, so the process-wide umask is safe to flip.
  const mode_t old_mask = ::umask(0117);
  const int rc = ::bind(fd.get(), reinterpret_cast<const sockaddr*>(&*addr), sizeof *addr);
  const int bind_errno = errno;
  ::umask(old_mask);
  if (rc != 0) {
    errno = bind_errno;
    return sysError("cannot bind " + path);
  }
  if (group != static_cast<gid_t>(-1) &&
      ::chown(path.c_str(), static_cast<uid_t>(-1), group) != 0) {
    logDebug("cannot give " + path + " to group " + std::to_string(group) + ": " +
             std::strerror(errno));
  }
  if (::listen(fd.get(), 128) != 0) return sysError("listen");
  return ListeningSocket{std::move(fd), false, path};
}

void removeControlSocket(const ListeningSocket& socket) {
  if (!socket.activated && !socket.path.empty()) ::unlink(socket.path.c_str());
}

}  // namespace procam::daemon
