// recalibrate = "on-drift": the correction steps a drift check decides on
// (daemon_drift.cpp): a camera re-registered (drift/camera_correction.hpp), the wall
// measured again by a coarse Gray pass (drift_scan.cpp) or, under on-drift-silent, from
// the content two cameras or one camera and the projector triangulate
// (drift/wall_from_views.hpp), the projector's pose and collineation fitted again
// (drift/projector_correction.hpp); each merged into rig.json atomically, a failed step
// escalating to a scan (drift_scan.cpp) or keeping the last good rig. Loop thread only.
#include <cstdio>

#include "blend/rig_tiles.hpp"
#include "daemon.hpp"
#include "drift/camera_correction.hpp"
#include "drift/projector_correction.hpp"
#include "drift/wall_from_views.hpp"
#include "log.hpp"
#include "protocol.hpp"
#include "rig_store.hpp"
#include "surface/surface_model.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// Keeps `projector` (or, given, `camera`) as it was before the first of the corrections
// since the output was last registered: restored when they do not converge.
void keepBefore(DriftRuntime::Output& o, const rig::RigProjector& projector,
                const rig::RigCamera* camera) {
  if (!o.before) o.before.emplace();
  rig::RigModel& b = *o.before;
  if (camera) {
    if (!b.camera(camera->name)) b.cameras.push_back(*camera);
  } else if (!b.projector(projector.name)) {
    b.projectors.push_back(projector);
  }
}

// `camera` (world -> camera) rigidly mounted on a projector that moved from `from` to `to`
// (world -> projector): the camera-from-projector pose stays.
geom::Pose carried(const geom::Pose& camera, const geom::Pose& from, const geom::Pose& to) {
  const geom::Pose rel = camera.relativeTo(from);
  return {rel.R * to.R, rel.R * to.t + rel.t};
}

// `camera`'s last check of the output as a view of the wall: its calibration, its
// misregistration and the map it used; nullopt unless the check is against this rig
// model (`generation`; so then is the reference, which a check sets before its result
// may be dropped and so is never older than `last`) and not too plain.
std::optional<drift::WallView> wallView(const rig::RigModel& rig, uint64_t generation,
                                        const DriftRuntime::Output& o, const std::string& camera) {
  const rig::RigCamera* cam = rig.camera(camera);
  auto v = o.views.find(camera);
  if (!cam || !cam->pose_known || v == o.views.end() || !v->second.last || !v->second.reference ||
      v->second.last_generation != generation || v->second.last->too_plain) {
    return std::nullopt;
  }
  return drift::WallView{&cam->model, &*v->second.last, &v->second.reference->map,
                         v->second.reference->grid};
}

// Why a correction was made: the misregistration, how long it was held, the threshold.
json heldOver(const drift::Misregistration& m, double held, double threshold) {
  return {{"misregistration_px", m.rms_px}, {"held_s", held}, {"threshold_px", threshold}};
}

// rig.json's provenance of a pose fitted again from `tiles` content tiles.
rig::Provenance fromContent(int tiles) {
  return {"drift correction: pose from content (" + std::to_string(tiles) + " tiles)", utcNow()};
}

}  // namespace

std::optional<drift::WallSeen> Daemon::movedWall(const std::string& output,
                                                 const std::string& camera) {
  DriftRuntime::Output& o = drift_rt_.outputs[output];
  if (!rig_.surface.plane) return std::nullopt;
  const auto here = wallView(rig_, rig_generation_, o, camera);
  const auto& above = o.views[camera].above;
  if (!here || !above) return std::nullopt;
  for (const std::string& name : o.cameras) {
    if (name == camera) continue;
    // Another camera that saw the drift too, checked since this one first saw it.
    const auto there = wallView(rig_, rig_generation_, o, name);
    if (!there || there->drift->rms_px <= config_.drift.threshold_px ||
        o.views[name].checked_at <= *above) {
      continue;
    }
    auto seen = drift::wallFromTwoViews(*here, *there, *rig_.surface.plane);
    if (!seen) {
      logInfo("drift: output '" + output + "': the wall from cameras '" + camera + "' and '" +
              name + "': " + seen.error().message);
      continue;
    }
    logInfo("drift: output '" + output + "': cameras '" + camera + "' and '" + name + "' see " +
            std::to_string(seen->points) + " content points " +
            std::to_string(1e3 * seen->offset_m) + " mm from the rig's wall (standard error " +
            std::to_string(1e3 * seen->offset_se_m) + " mm), turned " +
            std::to_string(seen->tilt_deg) +
            " deg: " + (drift::wallMoved(*seen) ? "the wall moved" : "the wall stands"));
    if (drift::wallMoved(*seen)) return *seen;
    return std::nullopt;
  }
  return std::nullopt;
}

std::optional<drift::WallSeen> Daemon::movedWallOneCamera(const std::string& output,
                                                          const std::string& camera) {
  DriftRuntime::Output& o = drift_rt_.outputs[output];
  const rig::RigProjector* p = rig_.projectorForOutput(output);
  const auto view = wallView(rig_, rig_generation_, o, camera);
  if (!rig_.surface.plane || !p || !p->pose_known || !p->intrinsics_known || !view) {
    return std::nullopt;
  }
  auto tile = blend::displayTile(*p, rig_.surface);
  if (!tile) return std::nullopt;
  auto seen = drift::wallFromOneCamera(*p, tile->projector_to_plane, *view, *rig_.surface.plane);
  if (!seen) {
    logInfo("drift: output '" + output + "': not a moved wall: " + seen.error().message);
    return std::nullopt;
  }
  logInfo("drift: output '" + output + "': the projector and camera '" + camera + "' see " +
          std::to_string(seen->points) + " content points " + std::to_string(1e3 * seen->offset_m) +
          " mm from the rig's wall (standard error " + std::to_string(1e3 * seen->offset_se_m) +
          " mm), turned " + std::to_string(seen->tilt_deg) + " deg; their rays " +
          std::to_string(1e3 * seen->gap_rms_m) +
          " mm RMS apart, a moved projector would have "
          "turned " +
          std::to_string(seen->projector_turn_deg) +
          " deg: " + (drift::wallMoved(*seen) ? "the wall moved" : "the wall stands"));
  if (!drift::wallMoved(*seen)) return std::nullopt;
  return *seen;
}

Result<rig::RigModel> Daemon::wallUpdate(const rig::RigModel& rig, const geom::Plane& plane,
                                         double rms_m) {
  // Every projector on the wall keeps its pose; those that kept a collineation with the
  // old plane get theirs from the pose and the new plane.
  rig::RigModel update;
  update.surface.plane = plane;
  update.surface.plane_rms_m = rms_m;
  for (const rig::RigProjector& p : rig.projectors) {
    if (!p.plane_homography) continue;
    if (!p.pose_known || !p.intrinsics_known || !p.scale_known) {
      return fail(ErrorCode::kNotFound,
                  "projector '" + p.name +
                      "' is known only by its collineation with the old wall, which the moved "
                      "wall does not carry");
    }
    update.projectors.push_back(p);
    update.projectors.back().plane_homography.reset();
  }
  return update;
}

void Daemon::correctSurface(const std::string& output, const std::string& camera,
                            const drift::Misregistration& m, const drift::WallSeen& wall,
                            const std::string& seen_by) {
  DriftRuntime::Output& o = drift_rt_.outputs[output];
  const double held = heldFor(o);
  if (config_.recalibrate == RecalibratePolicy::kOnDrift) {
    // Pattern frames allowed: the coarse Gray pass measures the wall from thousands of
    // nodes where the content gave tens of points. Refused before any frame is shown when
    // the wall could not be written.
    const rig::RigModel base = o.before ? rig::mergeRig(rig_, *o.before) : rig_;
    if (rig_.surface.plane) {
      if (auto can = wallUpdate(base, *rig_.surface.plane, 0); !can) {
        return unresolveDrift(output, camera, "surface",
                              can.error().message + "; the rig model stays as it was", m);
      }
    }
    char seen[160];
    std::snprintf(seen, sizeof seen,
                  "the content moved as a moved wall moves it: %.2f mm (standard error %.3f mm) "
                  "off the rig's wall, turned %.3f deg, ",
                  1e3 * wall.offset_m, 1e3 * wall.offset_se_m, wall.tilt_deg);
    return scanForDrift(output, camera, DriftScan::kCoarse,
                        seen + std::string("seen by ") + seen_by, m, true);
  }
  auto made = wallUpdate(rig_, drift::wallToKeep(wall), wall.rms_m);
  if (!made) {
    return unresolveDrift(output, camera, "surface",
                          made.error().message + "; the rig model stays as it was", m);
  }
  rig::RigModel update = std::move(*made);
  // The wall is measured, not fitted by passes: what was kept to restore after
  // corrections that do not converge belonged to the old wall and cannot come back.
  o.forgetBefore();
  json why = heldOver(m, held, config_.drift.threshold_px);
  why.update({{"wall_offset_mm", 1e3 * wall.offset_m},
              {"wall_offset_se_mm", 1e3 * wall.offset_se_m},
              {"wall_turned_deg", wall.tilt_deg},
              {"plane_kept", drift::wallTurned(wall) ? "fitted" : "shifted"}});
  logInfo("drift: output '" + output + "': the wall moved " + std::to_string(1e3 * wall.offset_m) +
          " mm (turned " + std::to_string(wall.tilt_deg) +
          " deg); the rig's plane measured again from " + std::to_string(wall.points) +
          " content points " + seen_by + " triangulated");
  writeDriftCorrection(output, std::move(update),
                       {{"output", output},
                        {"step", "surface"},
                        {"why", why},
                        {"points", wall.points},
                        {"triangulated_by", seen_by},
                        {"plane_rms_mm", 1e3 * wall.rms_m}},
                       "corrected-surface");
}

void Daemon::unresolveDrift(const std::string& output, const std::string& camera,
                            const std::string& step, const std::string& why,
                            const drift::Misregistration& m) {
  DriftRuntime::Output& o = drift_rt_.outputs[output];
  o.unresolved = true;
  o.scan = DriftScan::kNone;  // a later drift climbs the steps from the cheapest again
  o.last_correction = {{"step", step}, {"camera", camera}, {"ok", false}, {"why", why}};
  warn("drift: output '" + output + "' (camera '" + camera + "'): " + why);
  broadcast("drift", {{"output", output},
                      {"camera", camera},
                      {"state", "unresolved"},
                      {"step", step},
                      {"why", why},
                      {"check", misregistrationJson(m)}});
}

Result<std::optional<Daemon::MeshRewrite>> Daemon::ownMeshMoved(
    const rig::RigProjector& before, const rig::RigProjector& after,
    const render::PixelRays& rays) const {
  auto file = rig_.surface.meshes.find(before.name);
  auto loaded = rig_surfaces_.find(before.name);
  if (file == rig_.surface.meshes.end() || loaded == rig_surfaces_.end()) return std::nullopt;
  const geom::TriangleMesh& mesh = loaded->second->intersector.mesh();
  if (mesh.uv.size() != mesh.vertices.size()) return std::nullopt;  // no pixels to move
  // The lens is the projector's: framebuffer pixel m still shows pinhole pixel W(m)
  // ([Raskar02] §4.1.3), so the pixel that lights vertex X now is W^-1(P' X).
  const Mat34 P = after.model().projectionMatrix();
  surface::SurfaceMesh was, moved;
  was.vertices = moved.vertices = mesh.vertices;
  was.faces = moved.faces = mesh.faces;
  was.projector = mesh.uv;
  for (const Vec3& X : mesh.vertices) {
    const Vec3 q = P * X.homogeneous();
    if (!(q.z() > 0)) {
      return fail(ErrorCode::kDegenerate,
                  "a vertex of the projector's mesh is behind it in its new pose");
    }
    moved.projector.push_back(rays.toFramebuffer(q.hnormalized()));
  }
  return MeshRewrite{file->second, surface::toPly(moved), surface::toPly(was)};
}

void Daemon::correctDrift(const std::string& output, const std::string& camera,
                          const drift::Misregistration& m) {
  DriftRuntime::Output& o = drift_rt_.outputs[output];
  const rig::RigProjector* p = rig_.projectorForOutput(output);
  if (!p) return;
  const double held = heldFor(o);
  const auto giveUp = [&](const std::string& why) {
    escalateDrift(output, camera, "projector-pose", why, m);
  };
  const DriftRuntime::View& v = o.views[camera];
  std::map<std::string, std::string> meshes;
  std::optional<MeshRewrite> rewrite;
  Result<drift::ProjectorCorrection> c = fail(ErrorCode::kNotFound, "");
  if (v.reference && v.reference->rays) {
    // A surface mesh: the pose from the points the content landed on, and the
    // projector's own mesh, if it has one, told the pixels that light it now.
    c = drift::correctProjector(*p, v.reference->lit, m);
    if (!c) return giveUp("the projector's pose from the content: " + c.error().message);
    auto moved = ownMeshMoved(*p, c->projector, *v.reference->rays);
    if (!moved) return giveUp("the projector's mesh: " + moved.error().message);
    rewrite = std::move(*moved);
    if (rewrite) meshes[rewrite->file] = rewrite->text;
  } else {
    auto tile = blend::displayTile(*p, rig_.surface);
    if (!tile) return giveUp(tile.error().message);
    c = drift::correctProjector(*p, tile->projector_to_plane, m);
    if (!c) return giveUp("the projector's pose from the content: " + c.error().message);
  }
  rig::RigModel update;
  update.projectors.push_back(c->projector);
  update.projectors.back().calibrated = fromContent(c->tiles);
  keepBefore(o, *p, nullptr);
  if (rewrite) o.before_meshes.emplace(rewrite->file, std::move(rewrite->before));
  // Cameras mounted on the projector moved with it.
  for (const rig::RigCamera& cam : rig_.cameras) {
    if (cam.attached_to != p->name || !cam.pose_known || !p->pose_known) continue;
    keepBefore(o, *p, &cam);
    update.cameras.push_back(cam);
    update.cameras.back().model.pose = carried(cam.model.pose, p->pose, c->projector.pose);
  }
  const json why = heldOver(m, held, config_.drift.threshold_px);
  logInfo("drift: output '" + output + "': correcting projector '" + p->name +
          "' from the content (" + std::to_string(m.rms_px) + " px held " + std::to_string(held) +
          " s; " + std::to_string(c->tiles) + " tiles, pose fit " + std::to_string(c->pose_rms_px) +
          " px" + (meshes.empty() ? "" : "; its mesh's pixels moved with it") + ")");
  json event = {{"output", output},
                {"projector", p->name},
                {"step", "projector-pose"},
                {"why", why},
                {"tiles", c->tiles},
                {"pose_fit_px", c->pose_rms_px},
                {"surface", v.reference && v.reference->rays ? "mesh" : "plane"}};
  // The mesh file is written before rig.json: when rig.json is not, its old text goes back.
  std::function<void(const Result<std::string>&)> after;
  if (rewrite) {
    after = [this, file = rewrite->file,
             text = o.before_meshes.at(rewrite->file)](const Result<std::string>& written) {
      if (!written) writeRig({}, {{file, text}}, [](const Result<std::string>&) {});
    };
  }
  writeDriftCorrection(output, std::move(update), std::move(event), "corrected-pose",
                       std::move(meshes), std::move(after));
}

void Daemon::correctCamera(const std::string& output, const std::string& camera,
                           const drift::Misregistration& m) {
  DriftRuntime& d = drift_rt_;
  DriftRuntime::Output& o = d.outputs[output];
  const rig::RigProjector* p = rig_.projectorForOutput(output);
  const rig::RigCamera* cam = rig_.camera(camera);
  const DriftRuntime::View& v = o.views[camera];
  if (!p || !cam || !v.reference) return;
  const double held = heldFor(o);
  const auto giveUp = [&](const std::string& why) {
    unresolveDrift(output, camera, "camera-pose", why + "; the rig model stays as it was", m);
  };
  // The content's surface points: where the rig model says the projector lights them
  // (its check's, on a plane or a mesh).
  auto c = drift::correctCamera(*cam, v.reference->lit, m, v.reference->map, v.reference->grid);
  if (!c) return giveUp("the camera's pose from the content: " + c.error().message);
  rig::RigModel update;
  update.cameras.push_back(c->camera);
  update.cameras.back().calibrated = fromContent(c->tiles);
  keepBefore(o, *p, cam);
  json why = heldOver(m, held, config_.drift.threshold_px);
  why["registered_in"] = "another camera sees the output registered";
  logInfo("drift: output '" + output + "' misregistered in camera '" + camera +
          "' only: re-registering the camera from the content (" + std::to_string(m.rms_px) +
          " px held " + std::to_string(held) + " s; " + std::to_string(c->tiles) +
          " tiles, pose fit " + std::to_string(c->pose_rms_px) + " camera px)");
  writeDriftCorrection(output, std::move(update),
                       {{"output", output},
                        {"camera", camera},
                        {"step", "camera-pose"},
                        {"why", why},
                        {"tiles", c->tiles},
                        {"pose_fit_px", c->pose_rms_px}},
                       "corrected-camera");
}

void Daemon::abandonDrift(const std::string& output, const std::string& camera,
                          const std::string& step, const std::string& why,
                          const drift::Misregistration& m) {
  DriftRuntime::Output& o = drift_rt_.outputs[output];
  unresolveDrift(output, camera, step,
                 why + (o.before ? "; the devices as they were before the corrections go back"
                                 : "; the rig model stays as it was"),
                 m);
  restoreBeforeDrift(o);
}

void Daemon::restoreBeforeDrift(DriftRuntime::Output& o) {
  if (!o.before) return;
  drift_rt_.writing = true;
  writeRig(*o.before, o.before_meshes, [this](const Result<std::string>& written) {
    drift_rt_.writing = false;
    if (!written) {
      warn("drift: the rig model before the corrections: " + written.error().message);
    } else {
      refreshOutputs();
    }
  });
  o.forgetBefore();
}

void Daemon::writeDriftCorrection(const std::string& output, rig::RigModel update, json event,
                                  const char* state, std::map<std::string, std::string> meshes,
                                  std::function<void(const Result<std::string>&)> after) {
  drift_rt_.writing = true;
  writeRig(std::move(update), std::move(meshes),
           [this, output, event = std::move(event), state,
            after = std::move(after)](const Result<std::string>& written) mutable {
             DriftRuntime& d = drift_rt_;
             d.writing = false;
             if (after) after(written);
             auto it = d.outputs.find(output);
             if (it == d.outputs.end()) return;  // the output went away meanwhile
             DriftRuntime::Output& o = it->second;
             o.forgetDrift();
             if (!written) {
               o.scan = DriftScan::kNone;  // a scan that was not kept is not a step made
               event["state"] = "failed";
               event["error"] = written.error().message;
               o.last_correction = event;
               warn("drift: " + written.error().message + "; the rig model stays as it was");
               broadcast("drift", event);
               return;
             }
             ++o.passes;
             ++o.corrections;
             event["pass"] = o.passes;
             event["state"] = state;
             event["time"] = utcNow();
             o.last_correction = event;
             broadcast("drift", event);
             refreshOutputs();  // a new projector mapping moves the keystone
           });
}

}  // namespace procam::daemon
