#include "protocol.hpp"

namespace procam::daemon::proto {

using nlohmann::json;

namespace {
std::string line(const json& j) {
  // Replace invalid UTF-8 rather than throw: messages may quote user input.
  return j.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
}
}  // namespace

tl::expected<Request, Failure> parseRequest(std::string_view text) {
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    return tl::unexpected(Failure{nullptr, code::kParse, "request is not valid JSON"});
  }
  if (!j.is_object()) {
    return tl::unexpected(Failure{nullptr, code::kBadRequest, "request must be a JSON object"});
  }
  json id = nullptr;
  if (auto it = j.find("id"); it != j.end()) {
    if (!(it->is_string() || it->is_number_integer() || it->is_null())) {
      return tl::unexpected(
          Failure{nullptr, code::kBadRequest, "\"id\" must be a string, an integer or null"});
    }
    id = *it;
  }
  auto cmd = j.find("cmd");
  if (cmd == j.end() || !cmd->is_string() || cmd->get_ref<const std::string&>().empty()) {
    return tl::unexpected(
        Failure{id, code::kBadRequest, "request needs \"cmd\", a non-empty string"});
  }
  std::string name = cmd->get<std::string>();
  return Request{std::move(id), std::move(name), std::move(j)};
}

std::string versionBanner(const std::string& release) {
  return line({{"class", "VERSION"},
               {"release", release},
               {"proto_major", kMajor},
               {"proto_minor", kMinor}});
}

std::string reply(const std::string& cls, const json& id, json body) {
  json j = json::object();
  j["class"] = cls;
  j["id"] = id;
  if (body.is_object()) {
    for (auto& [k, v] : body.items()) {
      if (k != "class" && k != "id") j[k] = std::move(v);
    }
  }
  return line(j);
}

std::string error(const json& id, std::string_view code, std::string_view message) {
  return line({{"class", "ERROR"}, {"id", id}, {"code", code}, {"message", message}});
}

std::string event(std::string_view name, json body) {
  json j = json::object();
  j["class"] = "EVENT";
  j["id"] = nullptr;
  j["event"] = name;
  if (body.is_object()) {
    for (auto& [k, v] : body.items()) {
      if (k != "class" && k != "id" && k != "event") j[k] = std::move(v);
    }
  }
  return line(j);
}

void LineFramer::feed(std::string_view data) {
  buf_.append(data);
  for (;;) {
    const size_t nl = buf_.find('\n', scan_from_);
    if (nl == std::string::npos) {
      scan_from_ = buf_.size();
      if (!discarding_ && buf_.size() > max_) {
        ready_.push_back(Item{true, {}});
        discarding_ = true;
      }
      if (discarding_) {
        buf_.clear();
        scan_from_ = 0;
      }
      return;
    }
    if (discarding_) {
      discarding_ = false;  // the end of the oversized line
    } else if (nl > max_) {
      ready_.push_back(Item{true, {}});
    } else {
      std::string l = buf_.substr(0, nl);
      if (!l.empty() && l.back() == '\r') l.pop_back();
      ready_.push_back(Item{false, std::move(l)});
    }
    buf_.erase(0, nl + 1);
    scan_from_ = 0;
  }
}

bool LineFramer::next(Item& out) {
  if (ready_.empty()) return false;
  out = std::move(ready_.front());
  ready_.pop_front();
  return true;
}

}  // namespace procam::daemon::proto
