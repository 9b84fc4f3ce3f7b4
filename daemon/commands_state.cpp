// Commands that change or persist settings: pattern, content, save, reload,
// log-level (PROTOCOL.md).
#include "content_mesh.hpp"
#include "daemon.hpp"
#include "log.hpp"
#include "request_args.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {
constexpr const char* kReplacedContent = "replaced by a later content request";
}  // namespace

void Daemon::cmdPattern(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "name");
  auto name = args.string("name");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (!name) {
    replyTo(client, req, "PATTERN", {{"pattern", settings_.pattern}, {"shown", false}});
    return;
  }
  if (!isPatternName(*name)) {
    return errorTo(client, req, code::kBadArgument,
                   "unknown pattern '" + *name + "' (" + patternNames() + ")");
  }
  settings_.pattern = *name;
  // Rendered on a worker (with the keystone warp); answered once it is shown.
  server_->hold(client);
  refreshOutputs(
      [this, client, req, pattern = *name](bool drawn) {
        // A later `pattern` may have replaced this one before its frame was drawn.
        const bool shown = drawn && settings_.pattern == pattern;
        broadcast("pattern", {{"pattern", pattern}, {"shown", shown}});
        replyTo(client, req, "PATTERN", {{"pattern", pattern}, {"shown", shown}});
        server_->release(client);
      },
      true);
}

json Daemon::contentJson() const {
  if (live_content_) return liveContentJson();
  if (object_show_.prepared) return object_show_.prepared->info;
  if (!keystone_rt_.meshes.empty() || !keystone_rt_.mesh_images.empty()) {
    return keystone_rt_.mesh_info;
  }
  if (settings_.content.empty()) return nullptr;
  json j = {{"path", settings_.content}};
  if (content_info_.width > 0) j["size"] = {content_info_.width, content_info_.height};
  return j;
}

void Daemon::dropContent() {
  stopLiveContent();
  settings_.content.clear();
  content_info_ = {};
  keystone_rt_.content.reset();
  keystone_rt_.meshes.clear();
  keystone_rt_.mesh_images.clear();
  clearObjectContent();
}

void Daemon::cmdContent(ClientId client, const proto::Request& req) {
  if (req.body.value("action", json()) == "share") return cmdContentShare(client, req);
  if (req.body.value("action", json()) == "stream") return cmdContentStream(client, req);
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "path", "texture", "specular", "shininess");
  const std::string action = args.string("action").value_or("get");
  auto path = args.string("path");
  auto texture = args.string("texture");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  ObjectLook look;
  const bool look_args = texture || args.get("specular") || args.get("shininess");
  for (const char* key : {"specular", "shininess"}) {
    if (const json* v = args.get(key)) {
      if (!v->is_number())
        return errorTo(client, req, code::kBadArgument,
                       std::string("\"") + key + "\" must be a number");
      (std::string(key) == "specular" ? look.specular : look.shininess) = v->get<double>();
    }
  }
  if (look_args && (action != "load" || !path || !rig_.surface.object)) {
    return errorTo(client, req, code::kBadArgument,
                   "\"texture\", \"specular\" and \"shininess\" go with content load on a "
                   "rig with an object (object place)");
  }
  if (texture && path && !isMeshFile(*path)) {
    return errorTo(client, req, code::kBadArgument,
                   "\"texture\" goes with the object's model (.obj, .ply); an image loaded on an "
                   "object rig is the texture itself");
  }
  if (action == "get" || action == "clear") {
    if (path)
      return errorTo(client, req, code::kBadArgument, "content " + action + " takes no path");
    if (action == "clear") {
      ++content_requests_;
      dropContent();
      broadcast("content", {{"content", nullptr}});
      refreshOutputs({}, true);
    }
    replyTo(client, req, "CONTENT", {{"content", contentJson()}});
    return;
  }
  if (action != "load") {
    return errorTo(client, req, code::kBadArgument,
                   "unknown content action '" + action + "' (get, load, clear, share, stream)");
  }
  if (!path || path->empty()) {
    return errorTo(client, req, code::kBadArgument, "content load needs \"path\"");
  }
  if (refuseOverJobLimit(client, req)) return;
  if (isMeshFile(*path) && rig_.surface.object) {
    // An object rig: the model is the look painted on the object (object_content.hpp).
    look.file = *path;
    look.texture = texture.value_or("");
    return loadObjectContent(client, req, std::move(look));
  }
  if (rig_.surface.object) {
    // An image on an object rig: the texture of the rig's model, painted on the object.
    look.texture = *path;
    return loadObjectContent(client, req, std::move(look));
  }
  if (isMeshFile(*path)) {
    // 3D content (content_mesh.hpp): prepared on a worker, then shown instead of any image.
    const std::string file = *path;
    std::vector<MeshOutput> outputs;
    for (const auto& e : devices_.entries()) {
      if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
      MeshOutput o{e.name, std::nullopt, rig_.surface.plane, !rig_.surface.empty(), nullptr};
      const rig::RigProjector* p = rig_.projectorForOutput(e.name);
      if (p && p->pose_known && p->scale_known) o.projector = p->model();
      if (p && !o.plane) {
        if (auto surface = rigSurfaceFor(p->name)) {
          o.surface = std::shared_ptr<const geom::MeshIntersector>(surface, &surface->intersector);
        }
      }
      outputs.push_back(std::move(o));
    }
    const auto viewer = contentEye();
    const std::optional<Vec3> eye = viewer.first;
    const json eye_source = viewer.second;
    server_->hold(client);
    const uint64_t request = ++content_requests_;
    compute_worker_->submit(
        [this, client, req, file, outputs, eye, eye_source, access = contentAccess(), request] {
          auto prepared = std::make_shared<tl::expected<PreparedMesh, MeshFailure>>(
              prepareMeshContent(access, file, outputs, eye, eye_source));
          return [this, client, req, prepared, request] {
            if (!*prepared) {
              errorTo(client, req, (*prepared).error().code, (*prepared).error().message);
            } else if (request != content_requests_) {
              errorTo(client, req, code::kCancelled, kReplacedContent);
            } else {
              dropContent();
              keystone_rt_.meshes = std::move((*prepared)->meshes);
              keystone_rt_.mesh_images = std::move((*prepared)->images);
              keystone_rt_.mesh_info = std::move((*prepared)->info);
              followMeshViewer(**prepared);
              broadcast("content", {{"content", contentJson()}});
              refreshOutputs({}, true);
              replyTo(client, req, "CONTENT", {{"content", contentJson()}});
            }
            server_->release(client);
          };
        },
        answerFailure(client, req), client);
    return;
  }
  // Decoding may take long: done on a worker, applied back on the loop.
  const std::string op_id = "op-" + std::to_string(next_operation_++);
  auto cancelled = std::make_shared<std::atomic<bool>>(false);
  operations_[op_id] = Operation{"content-load", client, req.id, cancelled};
  server_->hold(client);
  operationEvent(
      client, "progress",
      {{"operation", op_id}, {"kind", "content-load"}, {"fraction", 0.0}, {"stage", "decoding"}});
  const uint64_t request = ++content_requests_;
  compute_worker_->submit(
      [this, client, req, op_id, cancelled, file = *path, access = contentAccess(), request] {
        auto decoded = decodeContent(access, file);
        std::shared_ptr<const cv::Mat> image = decoded ? decoded->image : nullptr;
        const std::string resolved = decoded ? decoded->path : std::string();
        const std::string failure = decoded ? std::string() : decoded.error().message;
        const char* failure_code = decoded ? "" : protoCode(decoded.error().code);
        return
            [this, client, req, op_id, cancelled, resolved, image, failure, failure_code, request] {
              operations_.erase(op_id);
              json finished = {{"operation", op_id}, {"kind", "content-load"}, {"ok", true}};
              // A later content request (another client's, queued in another lane) wins.
              if (request != content_requests_) cancelled->store(true);
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
                errorTo(client, req, code::kCancelled,
                        request != content_requests_ ? kReplacedContent : "content load cancelled");
              } else if (!failure.empty()) {
                errorTo(client, req, failure_code, failure);
              } else {
                dropContent();
                settings_.content = resolved;
                content_info_ = {image->cols, image->rows};
                keystone_rt_.content = image;
                broadcast("content", {{"content", contentJson()}});
                refreshOutputs({}, true);
                replyTo(client, req, "CONTENT", {{"content", contentJson()}, {"operation", op_id}});
              }
              server_->release(client);  // after the reply: a half-closed client may close now
            };
      },
      [this, client, req, op_id](const std::string& what) {
        operations_.erase(op_id);
        operationEvent(
            client, "finished",
            {{"operation", op_id}, {"kind", "content-load"}, {"ok", false}, {"error", what}});
        answerFailure(client, req)(what);
      },
      client);
}

void Daemon::cmdSave(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "");
  if (refuseOverJobLimit(client, req)) return;
  // fsync may block: the write runs on the I/O worker. Its one thread writes the
  // newest settings any client asked to save, so saves that queue up behind
  // each other (other clients' jobs may come between) write once and never
  // put older settings over newer ones.
  {
    std::lock_guard lock(save_slot_->mutex);
    save_slot_->text = settingsToJson(settings_);
    ++save_slot_->requested;
  }
  server_->hold(client);
  io_worker_->submit(
      [this, client, req, slot = save_slot_] {
        std::string text;
        uint64_t generation = 0;
        {
          std::lock_guard lock(slot->mutex);
          text = slot->text;
          generation = slot->requested;
          if (slot->written >= generation) {  // on disk already, by an earlier job
            return WorkerPool::Completion([this, client, req, bytes = text.size()] {
              replyTo(client, req, "SAVE", {{"path", settings_file_->path()}, {"bytes", bytes}});
              server_->release(client);
            });
          }
        }
        auto ok = settings_file_->write(text);
        if (ok) {
          std::lock_guard lock(slot->mutex);
          slot->written = std::max(slot->written, generation);
        }
        return WorkerPool::Completion([this, client, req, ok, bytes = text.size()] {
          if (!ok) {
            warn("save failed: " + ok.error().message);
            errorTo(client, req, code::kIo, ok.error().message);
          } else {
            logInfo("settings saved to " + settings_file_->path());
            replyTo(client, req, "SAVE", {{"path", settings_file_->path()}, {"bytes", bytes}});
          }
          server_->release(client);  // after the reply: a half-closed client may close now
        });
      },
      answerFailure(client, req), client);
}

Result<void> Daemon::reloadConfig() {
  if (options_.config_path.empty()) {
    return fail(ErrorCode::kNotFound, "procamd was started without a configuration file");
  }
  auto cfg = loadConfig(options_.config_path);
  if (!cfg) return tl::unexpected(cfg.error());
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
  setupDriftCheck();
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
