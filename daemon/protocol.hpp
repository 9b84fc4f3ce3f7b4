#pragma once
// The control protocol (daemon/PROTOCOL.md): newline-delimited JSON objects.
// Parsing of one request line, framing of the byte stream into lines with the
// 64 KiB limit, and the shapes of replies, errors and events.
#include <cstddef>
#include <deque>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "tl/expected.hpp"

namespace procam::daemon::proto {

inline constexpr int kMajor = 1;
inline constexpr int kMinor = 0;
inline constexpr size_t kMaxRequestBytes = 64 * 1024;  // newline excluded

// Error codes of ERROR replies.
namespace code {
inline constexpr const char* kParse = "parse-error";       // not JSON
inline constexpr const char* kBadRequest = "bad-request";  // JSON, but not a request
inline constexpr const char* kTooLarge = "too-large";  // over kMaxRequestBytes or a [limits] bound
inline constexpr const char* kUnknownCommand = "unknown-command";
inline constexpr const char* kBadArgument = "bad-argument";
inline constexpr const char* kUnavailable = "unavailable";  // not built / no device
inline constexpr const char* kNotFound = "not-found";
inline constexpr const char* kBusy = "busy";
inline constexpr const char* kCancelled = "cancelled";
inline constexpr const char* kFailed = "failed";  // the operation ran but found no result
inline constexpr const char* kTooFewPoints = "too-few-points";  // a fit got fewer than it needs
inline constexpr const char* kDegenerate = "degenerate";  // a fit's points admit no unique answer
inline constexpr const char* kForbidden = "forbidden";
inline constexpr const char* kIo = "io-error";
inline constexpr const char* kConfig = "config-error";
inline constexpr const char* kInternal = "internal-error";
}  // namespace code

struct Request {
  nlohmann::json id;  // string, integer or null
  std::string cmd;
  nlohmann::json body;  // the whole request object
};

struct Failure {
  nlohmann::json id;  // the request's id when it could be read, else null
  std::string code;
  std::string message;
};

// Parses one request line. Never throws.
tl::expected<Request, Failure> parseRequest(std::string_view line);

// Each returns one complete line, newline included.
std::string versionBanner(const std::string& release);
std::string reply(const std::string& cls, const nlohmann::json& id, nlohmann::json body = {});
std::string error(const nlohmann::json& id, std::string_view code, std::string_view message);
std::string event(std::string_view name, nlohmann::json body);

// Splits a byte stream into lines. A line longer than the limit is reported
// once as oversized and skipped up to its newline; the stream stays usable.
class LineFramer {
 public:
  explicit LineFramer(size_t max_line = kMaxRequestBytes) : max_(max_line) {}

  struct Item {
    bool oversized = false;
    std::string line;  // without the newline; empty when oversized
  };

  void feed(std::string_view data);
  bool next(Item& out);
  size_t buffered() const { return buf_.size(); }

 private:
  size_t max_;
  std::string buf_;
  size_t scan_from_ = 0;
  bool discarding_ = false;
  std::deque<Item> ready_;
};

}  // namespace procam::daemon::proto
