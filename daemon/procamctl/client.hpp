#pragma once
// A blocking client of the control socket: connects, checks the VERSION
// banner, sends requests and reads reply and event lines.
#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "protocol.hpp"
#include "tl/expected.hpp"
#include "core/unique_fd.hpp"

namespace procam::ctl {

enum ExitCode {
  kExitOk = 0,
  kExitError = 1,        // the daemon answered ERROR
  kExitUsage = 2,        // bad command line
  kExitConnect = 3,      // no daemon, or no permission on the socket
  kExitProtocol = 4,     // banner missing, major version mismatch, connection lost, timeout
  kExitUnavailable = 5,  // the daemon does not have what the command needs
};

struct ClientError {
  ExitCode exit;
  std::string message;
};

class Client {
 public:
  static tl::expected<Client, ClientError> connect(const std::string& path,
                                                   std::chrono::milliseconds timeout);

  const nlohmann::json& banner() const { return banner_; }
  tl::expected<void, ClientError> send(const nlohmann::json& request);
  // The next line as JSON; `timeout` < 0 waits forever.
  tl::expected<nlohmann::json, ClientError> next(std::chrono::milliseconds timeout);
  // Sends a request and returns its reply, skipping events in between
  // (passed to `on_event` when given).
  tl::expected<nlohmann::json, ClientError> call(
      nlohmann::json request, std::chrono::milliseconds timeout,
      const std::function<void(const nlohmann::json&)>& on_event = {});

 private:
  daemon::UniqueFd fd_;
  daemon::proto::LineFramer framer_{16 * 1024 * 1024};
  nlohmann::json banner_;
  int next_id_ = 1;
};

}  // namespace procam::ctl
