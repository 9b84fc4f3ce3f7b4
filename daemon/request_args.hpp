#pragma once
// Reading and checking the arguments of a request: unknown keys and wrong
// types are bad-argument errors that name the key.
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace procam::daemon {

class RequestArgs {
 public:
  explicit RequestArgs(const nlohmann::json& body) : body_(body) {}

  // The first key of the request that is neither cmd, id nor in `allowed`.
  std::optional<std::string> unknownKey(std::initializer_list<std::string_view> allowed) const;

  const nlohmann::json* get(const char* key) const;
  // nullopt when absent; sets error() when present with the wrong type.
  std::optional<std::string> string(const char* key);
  std::optional<bool> boolean(const char* key);

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  void setError(std::string message) {
    if (error_.empty()) error_ = std::move(message);
  }

 private:
  const nlohmann::json& body_;
  std::string error_;
};

}  // namespace procam::daemon

// In a command handler (client, req, errorTo in scope): answers bad-argument
// and returns when the request has a key outside the listed ones.
#define PROCAM_CHECK_KEYS(args, ...)                                                              \
  if (auto bad = (args).unknownKey({__VA_ARGS__})) {                                              \
    errorTo(client, req, code::kBadArgument, "unknown argument \"" + *bad + "\" for " + req.cmd); \
    return;                                                                                       \
  }
