// The control protocol's commands (PROTOCOL.md), run on the loop thread.

#include "daemon.hpp"
#include "log.hpp"
#include "request_args.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

bool Daemon::replyTo(ClientId client, const proto::Request& req, const std::string& cls,
                     json body) {
  return server_->send(client, proto::reply(cls, req.id, std::move(body)));
}

void Daemon::errorTo(ClientId client, const proto::Request& req, const char* error_code,
                     const std::string& message) {
  server_->send(client, proto::error(req.id, error_code, message));
}

WorkerPool::Failure Daemon::answerFailure(ClientId client, const proto::Request& req) {
  return [this, client, req](const std::string& what) {
    errorTo(client, req, proto::code::kInternal, "the job failed: " + what);
    server_->release(client);
  };
}

bool Daemon::refuseOverJobLimit(ClientId client, const proto::Request& req) {
  const size_t queued = io_worker_->queued(client) + compute_worker_->queued(client);
  const auto limit = config_.limits.client_jobs;
  if (queued < limit) return false;
  errorTo(client, req, proto::code::kTooLarge,
          "this client has " + std::to_string(queued) +
              " jobs queued already ([limits] client_jobs = " + std::to_string(limit) +
              "): wait for their replies");
  return true;
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
      {"version", &Daemon::cmdVersion},
      {"status", &Daemon::cmdStatus},
      {"devices", &Daemon::cmdDevices},
      {"watch", &Daemon::cmdWatch},
      {"calibrate", &Daemon::cmdCalibrate},
      {"cancel", &Daemon::cmdCancel},
      {"keystone", &Daemon::cmdKeystone},
      {"pattern", &Daemon::cmdPattern},
      {"content", &Daemon::cmdContent},
      {"object", &Daemon::cmdObject},
      {"save", &Daemon::cmdSave},
      {"reload", &Daemon::cmdReload},
      {"log-level", &Daemon::cmdLogLevel},
      {"tracker", &Daemon::cmdTracker},
      {"latency", &Daemon::cmdLatency},
      {"snapshot", &Daemon::cmdSnapshot},
      {"calibrate-camera", &Daemon::cmdCalibrateCamera},
  };
  for (const auto& [name, fn] : kCommands) {
    if (req.cmd != name) continue;
    // A handler's defect must not take the daemon down with every client's state:
    // the request is answered and the daemon keeps its last good state.
    try {
      (this->*fn)(client, req);
    } catch (const std::exception& e) {
      logError("'" + req.cmd + "' request failed: " + e.what());
      errorTo(client, req, code::kInternal, std::string("internal error: ") + e.what());
    }
    return;
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
          {"drift", driftPolicyJson()},
          {"operations", ops},
          {"log_level", logLevelName(logLevel())},
          {"outputs", outputsJson()},
          {"viewer", viewerJson()},
          {"capabilities", {{"calibrate", true}, {"auto_keystone", true}, {"render", true}}},
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
  for (const auto& e : devices_.entries()) {
    json entry = e.toJson();
    addReadingStats(e, entry);  // frames or samples, rate_hz, last_timestamp
    list.push_back(std::move(entry));
  }
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
            {"device-added", "device-removed", "progress", "finished", "views", "keystone",
             "pattern", "content", "config", "warning"}}});
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

}  // namespace procam::daemon
