#pragma once
// The listening control socket: taken from systemd (socket activation) when
// passed, else bound by the daemon with mode 0660, replacing a stale socket.
#include <sys/types.h>

#include <string>

#include "core/error.hpp"
#include "core/unique_fd.hpp"

namespace procam::daemon {

struct ListeningSocket {
  UniqueFd fd;
  bool activated = false;  // passed by systemd
  std::string path;        // the bound path; empty when activated
};

// `group`: owner group given to a bound socket (when permitted); (gid_t)-1
// leaves it unchanged.
Result<ListeningSocket> openControlSocket(const std::string& path, gid_t group);

// Removes the socket file of a bound (not activated) socket.
void removeControlSocket(const ListeningSocket& socket);

}  // namespace procam::daemon
