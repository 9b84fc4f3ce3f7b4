#include "request_args.hpp"

namespace procam::daemon {

std::optional<std::string> RequestArgs::unknownKey(
    std::initializer_list<std::string_view> allowed) const {
  for (const auto& [key, value] : body_.items()) {
    if (key == "cmd" || key == "id") continue;
    bool known = false;
    for (auto a : allowed) known = known || key == a;
    if (!known) return key;
  }
  return std::nullopt;
}

const nlohmann::json* RequestArgs::get(const char* key) const {
  auto it = body_.find(key);
  return it == body_.end() ? nullptr : &*it;
}

std::optional<std::string> RequestArgs::string(const char* key) {
  const auto* v = get(key);
  if (!v) return std::nullopt;
  if (!v->is_string()) {
    setError(std::string("\"") + key + "\" must be a string");
    return std::nullopt;
  }
  return v->get<std::string>();
}

std::optional<bool> RequestArgs::boolean(const char* key) {
  const auto* v = get(key);
  if (!v) return std::nullopt;
  if (!v->is_boolean()) {
    setError(std::string("\"") + key + "\" must be true or false");
    return std::nullopt;
  }
  return v->get<bool>();
}

}  // namespace procam::daemon
