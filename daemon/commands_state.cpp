// Commands that change or persist settings: pattern, content, save, reload,
// log-level (PROTOCOL.md).
#include <opencv2/imgcodecs.hpp>

#include "daemon.hpp"
#include "log.hpp"
#include "request_args.hpp"
#include "test_pattern.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

bool Daemon::showPattern() {
  bool shown = false;
  for (auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    const auto& raw = e.device.raw();
    uint32_t w = 0, h = 0;
    double hz = 0;
    if (raw.ops.output->get_mode(raw.self, &w, &h, &hz) != PROCAM_OK || w == 0 || h == 0) continue;
    RgbImage img = renderTestPattern(settings_.pattern, static_cast<int>(w), static_cast<int>(h));
    procam_image frame{w, h, w * 3, PROCAM_PIXEL_RGB8, img.pixels.data(), 0};
    char err[256] = {};
    if (raw.ops.output->show(raw.self, &frame, err, sizeof err - 1) == PROCAM_OK) {
      shown = true;
    } else {
      warn("output '" + e.name + "' could not show the pattern: " + err);
    }
  }
  return shown;
}

void Daemon::cmdPattern(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "name");
  auto name = args.string("name");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  bool shown = false;
  if (name) {
    if (!isPatternName(*name)) {
      return errorTo(client, req, code::kBadArgument,
                     "unknown pattern '" + *name + "' (" + patternNames() + ")");
    }
    settings_.pattern = *name;
    shown = showPattern();
    broadcast("pattern", {{"pattern", settings_.pattern}, {"shown", shown}});
  }
  replyTo(client, req, "PATTERN", {{"pattern", settings_.pattern}, {"shown", shown}});
}

json Daemon::contentJson() const {
  if (settings_.content.empty()) return nullptr;
  json j = {{"path", settings_.content}};
  if (content_info_.width > 0) j["size"] = {content_info_.width, content_info_.height};
  return j;
}

void Daemon::cmdContent(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "path");
  const std::string action = args.string("action").value_or("get");
  auto path = args.string("path");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (action == "get" || action == "clear") {
    if (path)
      return errorTo(client, req, code::kBadArgument, "content " + action + " takes no path");
    if (action == "clear") {
      settings_.content.clear();
      content_info_ = {};
      broadcast("content", {{"content", nullptr}});
    }
    replyTo(client, req, "CONTENT", {{"content", contentJson()}});
    return;
  }
  if (action != "load") {
    return errorTo(client, req, code::kBadArgument,
                   "unknown content action '" + action + "' (get, load, clear)");
  }
  if (!path || path->empty()) {
    return errorTo(client, req, code::kBadArgument, "content load needs \"path\"");
  }
  // Decoding may take long: done on a worker, applied back on the loop.
  const std::string op_id = "op-" + std::to_string(next_operation_++);
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  operations_[op_id] = Operation{"content-load", client, req.id, cancelled};
  server_->hold(client);
  operationEvent(
      client, "progress",
      {{"operation", op_id}, {"kind", "content-load"}, {"fraction", 0.0}, {"stage", "decoding"}});
  compute_worker_->submit([this, client, req, op_id, cancelled, file = *path] {
    cv::Mat image;
    std::string failure;
    try {
      image = cv::imread(file, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception& e) {
      failure = e.what();
    }
    const int w = image.cols, h = image.rows;
    if (failure.empty() && image.empty()) failure = "cannot read an image from " + file;
    return [this, client, req, op_id, cancelled, file, w, h, failure] {
      operations_.erase(op_id);
      json finished = {{"operation", op_id}, {"kind", "content-load"}, {"ok", true}};
      if (cancelled->load()) {
        finished["ok"] = false;
        finished["error"] = "cancelled";
      } else if (!failure.empty()) {
        finished["ok"] = false;
        finished["error"] = failure;
      } else {
        operationEvent(client, "progress",
                       {{"operation", op_id},
                        {"kind", "content-load"},
                        {"fraction", 1.0},
                        {"stage", "decoded"}});
      }
      operationEvent(client, "finished", finished);
      if (cancelled->load()) {
        errorTo(client, req, code::kCancelled, "content load cancelled");
      } else if (!failure.empty()) {
        errorTo(client, req, code::kIo, failure);
      } else {
        settings_.content = file;
        content_info_ = {w, h};
        broadcast("content", {{"content", contentJson()}});
        replyTo(client, req, "CONTENT", {{"content", contentJson()}, {"operation", op_id}});
      }
      server_->release(client);  // after the reply: a half-closed client may close now
    };
  });
}

void Daemon::cmdSave(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "");
  // fsync may block: the write runs on the I/O worker (one thread, so saves
  // land in order).
  server_->hold(client);
  io_worker_->submit([this, client, req, text = settingsToJson(settings_)] {
    auto ok = settings_file_->write(text);
    return [this, client, req, ok, bytes = text.size()] {
      if (!ok) {
        warn("save failed: " + ok.error().message);
        errorTo(client, req, code::kIo, ok.error().message);
      } else {
        logInfo("settings saved to " + settings_file_->path());
        replyTo(client, req, "SAVE", {{"path", settings_file_->path()}, {"bytes", bytes}});
      }
      server_->release(client);  // after the reply: a half-closed client may close now
    };
  });
}

Result<void> Daemon::reloadConfig() {
  if (options_.config_path.empty()) {
    return fail(ErrorCode::kNotFound, "procamd was started without a configuration file");
  }
  auto cfg = loadConfig(options_.config_path);
  if (!cfg) return tl::unexpected(cfg.error());
  if (cfg->auto_keystone) {
    warn("policy.auto_keystone is set, but this build has no keystone pipeline; ignored");
  }
  config_ = std::move(*cfg);
  setLogLevel(config_.log_level);
  server_->setOptions(serverOptions());
  // Reopen the configured devices (virtual-rig devices stay as they are).
  for (auto& e : devices_.entries()) {
    if (e.description.subsystem == "config") broadcast("device-removed", e.toJson());
  }
  std::vector<std::string> stale;
  for (auto& e : devices_.entries()) {
    if (e.description.subsystem == "config") stale.push_back(e.name);
  }
  for (const auto& name : stale) devices_.close(name);
  const size_t before = devices_.entries().size();
  openDevices();
  device_manager_->sync();
  for (size_t i = before; i < devices_.entries().size(); ++i) {
    broadcast("device-added", devices_.entries()[i].toJson());
  }
  broadcast("config", {{"config", config_.source}});
  logInfo("configuration reloaded from " + config_.source);
  return {};
}

void Daemon::cmdReload(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "");
  if (auto ok = reloadConfig(); !ok) {
    return errorTo(client, req, code::kConfig, ok.error().message);
  }
  replyTo(client, req, "RELOAD",
          {{"config", config_.source}, {"devices", devices_.entries().size()}});
}

void Daemon::cmdLogLevel(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "level");
  auto level = args.string("level");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (level) {
    auto parsed = parseLogLevel(*level);
    if (!parsed) return errorTo(client, req, code::kBadArgument, parsed.error().message);
    setLogLevel(*parsed);
    logInfo(std::string("log level set to ") + logLevelName(*parsed));
  }
  replyTo(client, req, "LOG-LEVEL", {{"level", logLevelName(logLevel())}});
}

}  // namespace procam::daemon
