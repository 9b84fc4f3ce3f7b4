// The rig's object and the look painted on it ([Raskar02] §5.2, shader lamps;
// PROTOCOL.md `object` and `content load` on an object rig). `object place` registers a
// given model to the rig from points picked on the physical object and located in the
// world (eq. 4.2) and keeps the model beside rig.json; `content load` of the same model
// with texture coordinates then paints it (object_content.hpp). The look is painted again
// when the rig changes, when an output comes or goes (its projector's share goes to the
// others and what none reaches is reported unlit) and, for a highlight, when the tracked
// viewer moves.
#include <cmath>

#include "content/mesh_content.hpp"
#include "daemon.hpp"
#include "json_matrix.hpp"
#include "log.hpp"
#include "request_args.hpp"
#include "shader_lamps/object_placement.hpp"
#include "shader_lamps/object_refinement.hpp"

namespace procam::daemon {

using nlohmann::json;
namespace code = proto::code;

namespace {

// The file a placed model is kept in, beside rig.json.
constexpr const char* kObjectModelFile = "object-model.ply";
// Points to place a model from: a handful are picked; a bound keeps a request small.
constexpr std::size_t kMaxPlacementPoints = 1024;
// A placement whose points miss the model by more than this (RMS) is refused by default:
// a mis-picked point or another object's model, not a few millimetres of picking.
constexpr double kDefaultMaxPlacementRmsM = 0.01;

struct PlacementResult {
  std::string ply;
  lamps::ObjectPlacement placement;
  std::size_t vertices = 0, faces = 0;
  bool textured = false;
};

}  // namespace

json Daemon::objectJson() const {
  if (!rig_.surface.object) return nullptr;
  const rig::RigObject& o = *rig_.surface.object;
  json j = {{"mesh", o.mesh},
            {"R", rowMajor(o.R)},
            {"t", vectorJson(o.t)},
            {"points", o.points},
            {"placed", {{"method", o.placed.method}, {"time", o.placed.time}}}};
  if (o.fit_rms_m >= 0) j["fit_rms_m"] = o.fit_rms_m;
  j["painted"] = object_show_.prepared != nullptr;
  return j;
}

void Daemon::cmdObject(ClientId client, const proto::Request& req) {
  RequestArgs args(req.body);
  PROCAM_CHECK_KEYS(args, "action", "model", "points", "max_rms_m", "max_distance_m");
  const std::string action = args.string("action").value_or("get");
  const auto model = args.string("model");
  if (!args.ok()) return errorTo(client, req, code::kBadArgument, args.error());
  if (action == "get") {
    if (model || args.get("points") || args.get("max_distance_m"))
      return errorTo(client, req, code::kBadArgument, "object get takes no arguments");
    replyTo(client, req, "OBJECT", {{"object", objectJson()}});
    return;
  }
  if (action == "clear") {
    if (model || args.get("points") || args.get("max_distance_m"))
      return errorTo(client, req, code::kBadArgument, "object clear takes no arguments");
    if (!rig_.surface.object) {
      replyTo(client, req, "OBJECT", {{"object", nullptr}});
      return;
    }
    if (refuseOverJobLimit(client, req)) return;
    server_->hold(client);
    ++object_edits_;
    ++object_writes_;
    io_worker_->submit(
        [this, client, req, dir = options_.state_dir] {
          auto edited = [&]() -> Result<rig::RigModel> {
            auto loaded = loadRig(dir);
            if (!loaded) return tl::unexpected(loaded.error());
            rig::RigModel rig = std::move(loaded->rig);
            rig.surface.object.reset();
            if (auto ok = rigStateFile(dir).write(rig::rigToJson(rig).dump(2) + "\n"); !ok)
              return tl::unexpected(ok.error());
            return rig;
          }();
          return [this, client, req, edited] {
            --object_writes_;
            if (!edited) {
              errorTo(client, req, code::kIo, "rig.json not written: " + edited.error().message);
            } else {
              rig_ = *edited;
              logInfo("the rig's object was cleared");
              replyTo(client, req, "OBJECT", {{"object", nullptr}});
              onRigChanged();
            }
            server_->release(client);
          };
        },
        [this, failed = answerFailure(client, req)](const std::string& what) {
          --object_writes_;
          failed(what);
        },
        client);
    return;
  }
  if (action == "refine") return objectRefine(client, req, args);
  if (action != "place")
    return errorTo(client, req, code::kBadArgument,
                   "unknown object action '" + action + "' (get, place, refine, clear)");
  if (args.get("max_distance_m"))
    return errorTo(client, req, code::kBadArgument, "max_distance_m is for object refine");
  if (!model || model->empty())
    return errorTo(client, req, code::kBadArgument, "object place needs \"model\", a mesh file");
  if (!isMeshFile(*model))
    return errorTo(client, req, code::kBadArgument, "\"model\" must be an .obj or .ply file");
  const json* points = args.get("points");
  if (!points || !points->is_array() || points->size() < lamps::kMinPlacementPoints ||
      points->size() > kMaxPlacementPoints) {
    return errorTo(client, req, code::kBadArgument,
                   "object place needs \"points\": " + std::to_string(lamps::kMinPlacementPoints) +
                       " to " + std::to_string(kMaxPlacementPoints) +
                       " of {\"model\": [x, y, z], \"world\": [x, y, z]}");
  }
  std::vector<Vec3> model_points, world_points;
  for (std::size_t i = 0; i < points->size(); ++i) {
    const json& p = (*points)[i];
    const auto m = p.is_object() && p.contains("model") ? vectorFromJson(p["model"]) : std::nullopt;
    const auto w = p.is_object() && p.contains("world") ? vectorFromJson(p["world"]) : std::nullopt;
    if (!m || !w)
      return errorTo(client, req, code::kBadArgument,
                     "point " + std::to_string(i) +
                         " must be {\"model\": [x, y, z], \"world\": [x, y, z]} of finite numbers");
    model_points.push_back(*m);
    world_points.push_back(*w);
  }
  double max_rms = kDefaultMaxPlacementRmsM;
  if (const json* v = args.get("max_rms_m")) {
    if (!v->is_number() || !(v->get<double>() > 0) || v->get<double>() > 1)
      return errorTo(client, req, code::kBadArgument, "\"max_rms_m\" must be in (0, 1] metres");
    max_rms = v->get<double>();
  }
  if (refuseOverJobLimit(client, req)) return;
  server_->hold(client);
  compute_worker_->submit(
      [this, client, req, file = *model, model_points, world_points, max_rms,
       access = contentAccess()] {
        auto placed = [&]() -> tl::expected<PlacementResult, MeshFailure> {
          auto bytes = readContentFile(access, file);
          if (!bytes)
            return tl::unexpected(
                MeshFailure{protoCode(bytes.error().code), bytes.error().message});
          const sim::MeshLimits limits{access.limits.mesh_vertices, access.limits.mesh_faces,
                                       access.limits.face_indices, access.limits.file_bytes};
          auto mesh = content::meshContentFromBytes(*bytes, file, limits);
          if (!mesh)
            return tl::unexpected(MeshFailure{protoCode(mesh.error().code), mesh.error().message});
          auto fit = lamps::placeObject(model_points, world_points);
          if (!fit)
            return tl::unexpected(MeshFailure{
                fit.error().code == ErrorCode::kDegenerate ? code::kDegenerate : code::kBadArgument,
                fit.error().message});
          PlacementResult out;
          out.placement = *fit;
          if (fit->rms_m > max_rms) {
            std::string list;
            for (std::size_t i = 0; i < out.placement.residuals_m.size(); ++i)
              list += (i ? ", " : "") + std::to_string(i) + ": " +
                      std::to_string(out.placement.residuals_m[i] * 1000).substr(0, 6) + " mm";
            return tl::unexpected(MeshFailure{
                code::kBadArgument, "the points miss the placed model by " +
                                        std::to_string(fit->rms_m * 1000) + " mm RMS (over " +
                                        std::to_string(max_rms * 1000) +
                                        " mm): a mis-picked point or another object's model? "
                                        "Per point: " +
                                        list});
          }
          out.ply = lamps::modelPly(mesh->mesh);
          out.vertices = mesh->mesh.vertices.size();
          out.faces = mesh->mesh.faces.size();
          out.textured = mesh->mesh.texcoord.size() == mesh->mesh.vertices.size();
          return out;
        }();
        auto result =
            std::make_shared<tl::expected<PlacementResult, MeshFailure>>(std::move(placed));
        return [this, client, req, file, result] {
          if (!*result) {
            errorTo(client, req, (*result).error().code, (*result).error().message);
            server_->release(client);
            return;
          }
          const PlacementResult& r = **result;
          rig::RigModel update;
          rig::RigObject object;
          object.mesh = kObjectModelFile;
          object.R = r.placement.R;
          object.t = r.placement.t;
          object.fit_rms_m = r.placement.rms_m;
          object.points = static_cast<long>(r.placement.residuals_m.size());
          object.placed = {"model " + std::filesystem::path(file).filename().string() +
                               " placed from " + std::to_string(r.placement.residuals_m.size()) +
                               " points",
                           utcNow()};
          update.surface.object = object;
          json reply = {
              {"fit_rms_m", r.placement.rms_m},
              {"fit_max_m", r.placement.max_m},
              {"residuals_m", r.placement.residuals_m},
              {"model",
               {{"vertices", r.vertices}, {"triangles", r.faces}, {"textured", r.textured}}}};
          ++object_edits_;
          ++object_writes_;
          writeObject(client, req, std::move(update), {{kObjectModelFile, r.ply}}, reply);
        };
      },
      answerFailure(client, req), client);
}

namespace {

// The rig's measured surface: each projector's mesh (unified in the overlaps), or the
// unified one when there is no other.
Result<std::vector<geom::TriangleMesh>> measuredMeshes(const rig::RigModel& rig,
                                                       const std::string& state_dir) {
  std::vector<std::string> files;
  for (const auto& [projector, file] : rig.surface.meshes) files.push_back(file);
  if (files.empty() && !rig.surface.unified_mesh.empty()) files.push_back(rig.surface.unified_mesh);
  if (files.empty())
    return fail(ErrorCode::kNotFound,
                "the rig has no measured surface meshes (calibrate with two cameras)");
  std::vector<geom::TriangleMesh> meshes;
  for (const std::string& file : files) {
    if (!rig::RigSurface::isPlainFileName(file))
      return fail(ErrorCode::kInvalidInput,
                  "surface mesh '" + file + "' is not a file name in the state directory");
    auto loaded = content::loadMeshContent(std::filesystem::path(state_dir) / file);
    if (!loaded) return tl::unexpected(loaded.error());
    meshes.push_back(std::move(loaded->mesh));
  }
  return meshes;
}

}  // namespace

// `object refine`: the placed model's pose refined against the surface calibration
// measured (lamps::refinePlacement); rig.json keeps the refined pose.
void Daemon::objectRefine(ClientId client, const proto::Request& req, RequestArgs& args) {
  if (args.get("model") || args.get("points") || args.get("max_rms_m"))
    return errorTo(client, req, code::kBadArgument, "object refine takes only max_distance_m");
  if (!rig_.surface.object)
    return errorTo(client, req, code::kUnavailable, "the rig has no object (object place)");
  lamps::RefineOptions options;
  if (const json* v = args.get("max_distance_m")) {
    if (!v->is_number() || !(v->get<double>() >= options.final_distance_m) ||
        v->get<double>() > 0.1)
      return errorTo(client, req, code::kBadArgument,
                     "\"max_distance_m\" must be from 0.003 to 0.1 metres");
    options.max_distance_m = v->get<double>();
  }
  // Refined from the object as rig.json will hold it, not one a write is replacing.
  if (object_writes_ > 0)
    return errorTo(client, req, code::kBusy, "the rig's object is being written; try again");
  if (refuseOverJobLimit(client, req)) return;
  server_->hold(client);
  compute_worker_->submit(
      [this, client, req, rig = rig_, options, dir = options_.state_dir, edits = object_edits_] {
        const rig::RigObject& object = *rig.surface.object;
        auto refined = std::make_shared<Result<lamps::ObjectRefinement>>(
            [&]() -> Result<lamps::ObjectRefinement> {
              auto meshes = measuredMeshes(rig, dir);
              if (!meshes) return tl::unexpected(meshes.error());
              if (!rig::RigSurface::isPlainFileName(object.mesh))
                return fail(ErrorCode::kInvalidInput, "object mesh '" + object.mesh +
                                                          "' is not a file name in the state "
                                                          "directory");
              auto model = content::loadMeshContent(std::filesystem::path(dir) / object.mesh);
              if (!model) return tl::unexpected(model.error());
              lamps::ObjectPlacement start;
              start.R = object.R;
              start.t = object.t;
              return lamps::refinePlacement(*meshes, model->mesh, start, options);
            }());
        return [this, client, req, object, refined, edits] {
          // Another place, clear or refine started writing since (its rig.json merge may
          // still be on its way): this pose is of an object that is no more.
          if (edits != object_edits_) {
            errorTo(client, req, code::kCancelled, "the rig's object changed meanwhile");
            server_->release(client);
            return;
          }
          if (!*refined) {
            const ErrorCode c = refined->error().code;
            errorTo(client, req,
                    c == ErrorCode::kIo             ? code::kIo
                    : c == ErrorCode::kNotFound     ? code::kUnavailable
                    : c == ErrorCode::kDegenerate   ? code::kDegenerate
                    : c == ErrorCode::kTooFewPoints ? code::kTooFewPoints
                                                    : code::kBadArgument,
                    "object refine: " + refined->error().message);
            server_->release(client);
            return;
          }
          const lamps::ObjectRefinement& r = **refined;
          rig::RigModel update;
          rig::RigObject moved = object;
          moved.R = r.placement.R;
          moved.t = r.placement.t;
          moved.fit_rms_m = r.placement.rms_m;
          moved.points = r.points;
          // "refined from N points of the measured surface (how it was placed)", the
          // placement named once however often it is refined.
          const std::string prefix = "refined from ";
          std::string placed_by = object.placed.method;
          const std::size_t open = placed_by.find(" (");
          if (placed_by.rfind(prefix, 0) == 0 && open != std::string::npos &&
              placed_by.back() == ')')
            placed_by = placed_by.substr(open + 2, placed_by.size() - open - 3);
          moved.placed = {prefix + std::to_string(r.points) + " points of the measured surface (" +
                              placed_by + ")",
                          utcNow()};
          update.surface.object = moved;
          json free = json::array();
          for (const lamps::FreeDirection& f : r.free)
            free.push_back({{"kind", f.turn ? "turn" : "slide"},
                            {"axis", vectorJson(f.axis)},
                            {"through", vectorJson(f.through)}});
          json reply = {{"refined",
                         {{"free", free},
                          {"points", r.points},
                          {"candidates", r.candidates},
                          {"iterations", r.iterations},
                          {"rms_m", r.placement.rms_m},
                          {"max_m", r.placement.max_m},
                          {"moved_m", r.moved_m},
                          {"turned_deg", r.turned_deg}}}};
          logInfo("the rig's object refined from " + std::to_string(r.points) +
                  " measured points: moved " + std::to_string(r.moved_m * 1000) + " mm, turned " +
                  std::to_string(r.turned_deg) + " deg" +
                  (r.free.empty() ? std::string()
                                  : "; " + std::to_string(r.free.size()) +
                                        " direction(s) the measured surface does not fix kept "
                                        "as placed"));
          ++object_edits_;
          ++object_writes_;
          writeObject(client, req, std::move(update), {}, reply);
        };
      },
      answerFailure(client, req), client);
}

void Daemon::writeObject(ClientId client, const proto::Request& req, rig::RigModel update,
                         std::map<std::string, std::string> files, json reply) {
  writeRig(std::move(update), std::move(files),
           [this, client, req, reply](const Result<std::string>& path) mutable {
             --object_writes_;
             if (!path) {
               errorTo(client, req, code::kIo, path.error().message);
             } else {
               reply["path"] = *path;
               reply["object"] = objectJson();
               replyTo(client, req, "OBJECT", reply);
             }
             server_->release(client);
           });
}

std::vector<ObjectOutput> Daemon::objectOutputs() const {
  std::vector<ObjectOutput> out;
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    if (auto mode = outputMode(e.device.raw())) out.push_back({e.name, *mode});
  }
  return out;
}

void Daemon::clearObjectContent() {
  const uint64_t generation = object_show_.generation + 1;
  object_show_ = ObjectShow{};
  object_show_.generation = generation;
}

namespace {

bool sameOutputs(const std::vector<ObjectOutput>& a, const std::vector<ObjectOutput>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const ObjectOutput& x, const ObjectOutput& y) {
                      return x.name == y.name && x.mode == y.mode;
                    });
}

}  // namespace

void Daemon::loadObjectContent(ClientId client, const proto::Request& req, ObjectLook look) {
  server_->hold(client);
  const uint64_t request = ++content_requests_;
  const std::vector<ObjectOutput> outputs = objectOutputs();
  compute_worker_->submit(
      [this, client, req, look, rig = rig_, outputs, viewer = contentEye(),
       dir = options_.state_dir, access = contentAccess(), request,
       rig_generation = rig_generation_] {
        auto prepared = std::make_shared<tl::expected<PreparedObject, MeshFailure>>(
            prepareObjectContent(access, dir, rig, look, outputs, viewer.first, viewer.second));
        return [this, client, req, look, prepared, request, viewer, outputs, rig_generation] {
          if (!*prepared) {
            errorTo(client, req, (*prepared).error().code, (*prepared).error().message);
          } else if (request != content_requests_) {
            errorTo(client, req, code::kCancelled, "replaced by a later content request");
          } else {
            dropContent();
            object_show_.look = look;
            object_show_.rig_generation = rig_generation;
            object_show_.prepared = std::make_shared<const PreparedObject>(std::move(**prepared));
            if (object_show_.prepared->view_dependent && viewer.first) {
              object_show_.eye = *viewer.first;
              if (viewer.second.value("source", "") == "tracker")
                object_show_.tracker = viewer.second.value("tracker", "");
            }
            broadcast("content", {{"content", contentJson()}});
            refreshOutputs({}, true);
            replyTo(client, req, "CONTENT", {{"content", contentJson()}});
            // The rig or the outputs changed while it was painted: again for them.
            if (rig_generation != rig_generation_ || !sameOutputs(outputs, objectOutputs()))
              repaintObject("the rig or the outputs changed while the look was loaded");
          }
          server_->release(client);
        };
      },
      answerFailure(client, req), client);
}

void Daemon::repaintObject(const std::string& why) {
  ObjectShow& s = object_show_;
  if (!s.look) return;
  if (s.in_flight) {
    s.again = true;
    return;
  }
  if (!rig_.surface.object) {
    warn("object content cleared: the rig model no longer has an object");
    clearObjectContent();
    broadcast("content", {{"content", contentJson()}});
    refreshOutputs({}, true);
    return;
  }
  const auto viewer = contentEye();
  const std::optional<Vec3> eye = viewer.first;
  const json eye_source = viewer.second;
  s.in_flight = true;
  s.again = false;
  logInfo("painting the object again: " + why);
  compute_worker_->submit(
      [this, look = *s.look, rig = rig_, outputs = objectOutputs(), eye, eye_source,
       dir = options_.state_dir, access = contentAccess(), generation = s.generation,
       rig_generation = rig_generation_] {
        auto prepared = std::make_shared<tl::expected<PreparedObject, MeshFailure>>(
            prepareObjectContent(access, dir, rig, look, outputs, eye, eye_source));
        return [this, prepared, generation, eye, rig_generation] {
          ObjectShow& s = object_show_;
          if (s.generation != generation) return;  // other content meanwhile
          s.in_flight = false;
          if (!*prepared && s.rig_generation != rig_generation) {
            // Frames made for another object or placement would light the wrong places.
            warn("object content cleared: the look does not fit the rig as it is now: " +
                 (*prepared).error().message);
            clearObjectContent();
            broadcast("content", {{"content", contentJson()}});
            refreshOutputs({}, true);
            return;
          }
          if (!*prepared) {
            // Same rig, fewer outputs than it can paint with: the last good frames stay
            // shown until the outputs come back.
            warn("object content not painted again: " + (*prepared).error().message);
          } else {
            if ((*prepared)->view_dependent) {
              (*prepared)->info["display"]["view_updates"] = s.updates;
              if (eye) s.eye = *eye;
            }
            s.prepared = std::make_shared<const PreparedObject>(std::move(**prepared));
            s.rig_generation = rig_generation;
            broadcast("content", {{"content", contentJson()}});
            refreshOutputs({}, true);
          }
          if (s.again) repaintObject("changed while painting");
        };
      },
      [this, generation = s.generation](const std::string& what) {
        warn("object content not painted again: " + what);
        if (object_show_.generation != generation) return;
        object_show_.in_flight = false;
        if (object_show_.again) repaintObject("changed while painting");
      });
}

void Daemon::onObjectViewerSample() {
  ObjectShow& s = object_show_;
  if (!s.prepared || !s.prepared->view_dependent || s.tracker.empty() || s.in_flight) return;
  auto latest = trackers_.latest.find(s.tracker);
  if (latest == trackers_.latest.end()) return;
  const Vec3 eye = latest->second.world;
  if ((eye - s.eye).norm() <= config_.content_viewer_threshold_m) return;
  // Only the highlight moves: the views, weights and gains stay, each frame is shaded
  // again for the new eye on the compute worker ([Raskar02] §5.2.3).
  s.in_flight = true;
  const Vec3 shaded_before = s.eye;
  s.eye = eye;
  compute_worker_->submit(
      [this, prepared = s.prepared, eye, generation = s.generation, shaded_before] {
        json projectors;
        auto frames =
            std::make_shared<Result<std::map<std::string, std::shared_ptr<const cv::Mat>>>>(
                paintObjectFrames(*prepared, eye, &projectors));
        return [this, prepared, frames, projectors, eye, generation, shaded_before] {
          ObjectShow& s = object_show_;
          if (s.generation != generation || s.prepared != prepared) {
            if (s.generation == generation) s.in_flight = false;
            if (s.generation == generation && s.again) repaintObject("changed while painting");
            return;
          }
          s.in_flight = false;
          if (!*frames) {
            warn("object content not shaded for the moved viewer: " + frames->error().message);
            s.eye = shaded_before;  // the frames shown are still for that eye
          } else {
            auto next = std::make_shared<PreparedObject>(*prepared);
            next->frames = std::move(**frames);
            next->info["projectors"] = projectors;
            ++s.updates;
            next->info["display"]["viewer"]["position"] = vectorJson(eye);
            next->info["display"]["view_updates"] = s.updates;
            s.prepared = std::move(next);
            refreshOutputs();
          }
          if (s.again) return repaintObject("changed while painting");
          onObjectViewerSample();  // the viewer may have moved on meanwhile
        };
      },
      [this, generation = s.generation, shaded_before](const std::string& what) {
        warn("object content not shaded for the moved viewer: " + what);
        if (object_show_.generation != generation) return;
        object_show_.in_flight = false;
        object_show_.eye = shaded_before;
        if (object_show_.again) repaintObject("changed while painting");
      });
}

void Daemon::watchObjectOutputs() {
  device_manager_->onDeviceAdded([this](const DeviceEntry& e) {
    if (e.description.family == PROCAM_FAMILY_OUTPUT && object_show_.look)
      repaintObject("output '" + e.name + "' came");
  });
  device_manager_->onDeviceRemoved([this](const DeviceEntry& e) {
    if (e.description.family == PROCAM_FAMILY_OUTPUT && object_show_.look)
      repaintObject("output '" + e.name + "' went away");
  });
}

}  // namespace procam::daemon
