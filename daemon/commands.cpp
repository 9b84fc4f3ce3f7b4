// The control protocol's commands (PROTOCOL.md), run on the loop thread.

#include "daemon.hpp"
#include "geometry/homography.hpp"
#include "log.hpp"
#include "request_args.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

// Present in the protocol; answered with "unavailable" until the pipeline
// behind them is part of the build.
constexpr const char* kNoCalibration =
    "calibration needs the structured-light pipeline, which this procamd does not include";
constexpr const char* kNoAutoKeystone =
    "automatic keystone needs the keystone pipeline, which this procamd does not include";

json quadJson(const Quad& q) {
  json a = json::array();
  for (const auto& p : q) a.push_back({p[0], p[1]});
  return a;
}

}  // namespace

bool Daemon::replyTo(ClientId client, const proto::Request& req, const std::string& cls,
                     json body) {
  return server_->send(client, proto::reply(cls, req.id, std::move(body)));
}

void Daemon::errorTo(ClientId client, const proto::Request& req, const char* error_code,
                     const std::string& message) {
  server_->send(client, proto::error(req.id, error_code, message));
}

void Daemon::broadcast(const std::string& event, json body) {
  const std::string line = proto::event(event, std::move(body));
  // Copy the ids: a send may drop a slow watcher (removed later, on reap).
  std::vector<ClientId> ids;
  for (const auto& [id, watch_id] : watchers_) ids.push_back(id);
  for (ClientId id : ids) server_->send(id, line);
}

void Daemon::operationEvent(ClientId owner, const std::string& event, json body) {
  const std::string line = proto::event(event, std::move(body));
  std::vector<ClientId> ids;
  for (const auto& [id, watch_id] : watchers_) ids.push_back(id);
  if (!watchers_.count(owner)) ids.push_back(owner);
  for (ClientId id : ids) server_->send(id, line);
}

void Daemon::onDisconnect(ClientId client) {
  watchers_.erase(client);
  for (auto& [op_id, op] : operations_) {
    if (op.client == client) op.cancelled->store(true);  // nobody waits for it any more
  }
}

void Daemon::handle(ClientId client, const proto::Request& req) {
  using Handler = void (Daemon::*)(ClientId, const proto::Request&);
  static const std::pair<const char*, Handler> kCommands[] = {
      {"version", &Daemon::cmdVersion},     {"status", &Daemon::cmdStatus},
      {"devices", &Daemon::cmdDevices},     {"watch", &Daemon::cmdWatch},
      {"calibrate", &Daemon::cmdCalibrate}, {"cancel", &Daemon::cmdCancel},
      {"keystone", &Daemon::cmdKeystone},   {"pattern", &Daemon::cmdPattern},
      {"content", &Daemon::cmdContent},     {"save", &Daemon::cmdSave},
      {"reload", &Daemon::cmdReload},       {"log-level", &Daemon::cmdLogLevel},
  };
  for (const auto& [name, fn] : kCommands) {
    if (req.cmd == name) {
      (this->*fn)(client, req);
      return;
    }
  }
  std::string list;
  for (const auto& [name, fn] : kCommands) list += (list.empty() ? "" : ", ") + std::string(name);
  errorTo(client, req, code::kUnknownCommand, "unknown command '" + req.cmd + "' (" + list + ")");
}

void Daemon::cmdVersion(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "");
  replyTo(client, req, "VERSION",
          {{"release", kRelease},
           {"proto_major", proto::kMajor},
           {"proto_minor", proto::kMinor},
           {"plugin_abi", PROCAM_PLUGIN_ABI_VERSION}});
}

json Daemon::statusJson() const {
  const auto uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_);
  json devices = json::object();
  for (procam_family f :
       {PROCAM_FAMILY_OUTPUT, PROCAM_FAMILY_CAMERA, PROCAM_FAMILY_TILT, PROCAM_FAMILY_TRACKER}) {
    devices[plugins::familyName(f)] = devices_.count(f);
  }
  json ops = json::array();
  for (const auto& [id, op] : operations_) ops.push_back({{"operation", id}, {"kind", op.kind}});
  return {{"release", kRelease},
          {"pid", static_cast<int64_t>(::getpid())},
          {"uptime_s", uptime.count()},
          {"sim", options_.sim_scene.empty() ? json(nullptr) : json(options_.sim_scene)},
          {"config", config_.source.empty() ? json(nullptr) : json(config_.source)},
          {"state_dir", options_.state_dir},
          {"devices", devices},
          {"clients", server_->clientCount()},
          {"watchers", watchers_.size()},
          {"keystone", keystoneJson()},
          {"pattern", settings_.pattern},
          {"content", contentJson()},
          {"recalibrate", recalibratePolicyName(config_.recalibrate)},
          {"operations", ops},
          {"log_level", logLevelName(logLevel())},
          {"capabilities", {{"calibrate", false}, {"auto_keystone", false}, {"render", false}}},
          {"warnings", warnings_}};
}

void Daemon::cmdStatus(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "");
  replyTo(client, req, "STATUS", statusJson());
}

void Daemon::cmdDevices(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "");
  json list = json::array();
  for (const auto& e : devices_.entries()) list.push_back(e.toJson());
  json drivers = json::array();
  for (const auto& d : registry_.drivers()) {
    drivers.push_back(
        {{"name", d.name()}, {"family", plugins::familyName(d.family())}, {"origin", d.origin}});
  }
  replyTo(client, req, "DEVICES", {{"devices", list}, {"drivers", drivers}});
}

void Daemon::cmdWatch(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "enable");
  const bool enable = args.boolean("enable").value_or(true);
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (enable) {
    watchers_[client] = req.id;
  } else {
    watchers_.erase(client);
  }
  replyTo(client, req, "WATCH",
          {{"enabled", enable},
           {"events",
            {"device-added", "device-removed", "progress", "finished", "keystone", "pattern",
             "content", "config", "warning"}}});
}

void Daemon::cmdCalibrate(ClientId client, const proto::Request& req) {
  errorTo(client, req, code::kUnavailable, kNoCalibration);
}

void Daemon::cmdCancel(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "operation");
  auto which = args.string("operation");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  json cancelled = json::array();
  for (auto& [id, op] : operations_) {
    if ((which && *which == id) || (!which && op.client == client)) {
      op.cancelled->store(true);
      cancelled.push_back(id);
    }
  }
  if (cancelled.empty()) {
    return errorTo(
        client, req, code::kNotFound,
        which ? "no running operation '" + *which + "'" : "this client has no running operation");
  }
  replyTo(client, req, "CANCEL", {{"cancelled", cancelled}});
}

json Daemon::keystoneJson() const {
  json j = {{"auto", settings_.auto_keystone},
            {"corners", settings_.keystone ? quadJson(*settings_.keystone) : json(nullptr)},
            {"homography", nullptr},
            {"output_size", nullptr}};
  auto* self = const_cast<Daemon*>(this);  // device queries do not change the set
  if (DeviceEntry* out = self->devices_.firstUsable(PROCAM_FAMILY_OUTPUT)) {
    uint32_t w = 0, h = 0;
    double hz = 0;
    const auto& raw = out->device.raw();
    if (raw.ops.output->get_mode(raw.self, &w, &h, &hz) == PROCAM_OK && w > 1 && h > 1) {
      j["output_size"] = {w, h};
      if (settings_.keystone) {
        // The pre-warp of seed §3.2.5: full-frame pixel centres to the corners.
        const std::array<Vec2, 4> frame{Vec2(0, 0), Vec2(w - 1.0, 0), Vec2(w - 1.0, h - 1.0),
                                        Vec2(0, h - 1.0)};
        std::array<Vec2, 4> corners;
        for (int i = 0; i < 4; ++i)
          corners[i] = Vec2((*settings_.keystone)[i][0], (*settings_.keystone)[i][1]);
        if (auto H = geom::homographyFrom4(frame, corners)) {
          const Mat3 Hn = *H / (*H)(2, 2);
          j["homography"] = json::array();
          for (int r = 0; r < 3; ++r) j["homography"].push_back({Hn(r, 0), Hn(r, 1), Hn(r, 2)});
        }
      }
    }
  }
  return j;
}

void Daemon::cmdKeystone(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "corners", "enable");
  const std::string action = args.string("action").value_or("get");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (action == "get") {
    if (args.get("corners") || args.get("enable")) {
      return errorTo(client, req, code::kBadArgument, "keystone get takes no arguments");
    }
  } else if (action == "set") {
    const json* corners = args.get("corners");
    if (!corners) {
      return errorTo(client, req, code::kBadArgument,
                     "keystone set needs \"corners\": 4 [x, y] pairs, or null to clear");
    }
    if (corners->is_null()) {
      settings_.keystone.reset();
    } else {
      if (!corners->is_array() || corners->size() != 4) {
        return errorTo(client, req, code::kBadArgument, "\"corners\" must be 4 [x, y] pairs");
      }
      Quad q{};
      for (size_t i = 0; i < 4; ++i) {
        const json& p = (*corners)[i];
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
          return errorTo(client, req, code::kBadArgument, "\"corners\" must be 4 [x, y] pairs");
        }
        q[i] = {p[0].get<double>(), p[1].get<double>()};
      }
      if (auto ok = validateQuad(q); !ok) {
        return errorTo(client, req, code::kBadArgument, ok.error().message);
      }
      settings_.keystone = q;
    }
    broadcast("keystone", keystoneJson());
  } else if (action == "auto") {
    auto enable = args.boolean("enable");
    if (!args.ok() || !enable) {
      return errorTo(client, req, code::kBadArgument, "keystone auto needs \"enable\": true|false");
    }
    if (*enable) return errorTo(client, req, code::kUnavailable, kNoAutoKeystone);
    settings_.auto_keystone = false;
    broadcast("keystone", keystoneJson());
  } else {
    return errorTo(client, req, code::kBadArgument,
                   "unknown keystone action '" + action + "' (get, set, auto)");
  }
  replyTo(client, req, "KEYSTONE", keystoneJson());
}

}  // namespace procam::daemon
