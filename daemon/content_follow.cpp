// 3D content follows a tracked viewer (PROTOCOL.md `content`): while a mesh is shown and
// its viewer came from a tracker, a sample that moved the viewer more than
// [content] viewer_threshold_m from the eye of the last drawing recomputes only the
// view-dependent matrix A'4x4 P_T for the new eye (S and A stay, [Raskar02] §4.2.2-4.2.3; the
// mesh stays where it was placed in the world) and draws the outputs again. One such
// frame is in flight at a time and they start at most once per output frame period; a
// viewer who does not move causes no work.
//
// Why 5 mm by default: moving the eye by δ parallel to the plane moves the wall image of
// a point h in front of the plane, seen from distance d, by δ h / (d - h) (similar
// triangles); placement keeps h <= d / 4, so the stale image is off by at most δ / 3,
// 1.7 mm for 5 mm: about one projector pixel at a 3 m throw with f = 2400 px
// (wall_oblique: 1.25 mm per pixel head-on, more obliquely). Two samples of a still
// viewer differ by σ√2 per axis; for tracker noise σ = 1 mm, 5 mm is 3.5 of that and is
// exceeded by 0.6 % of samples, for σ = 0.5 mm practically never. A noisier tracker
// (the sim's dome3: σ = 2 mm) wants a larger threshold.
#include "content_mesh.hpp"
#include "daemon.hpp"
#include "log.hpp"

namespace procam::daemon {

using nlohmann::json;

Result<std::map<std::string, Mat4>> meshViewMatrices(const std::map<std::string, MeshView>& views,
                                                     const Vec3& eye) {
  std::map<std::string, Mat4> out;
  for (const auto& [name, v] : views) {
    content::PlanarView view = v.view;
    view.eye = eye;
    auto m = content::planar3dForViewer(view, v.S);
    if (!m) return tl::unexpected(m.error());
    out[name] = *m;
  }
  return out;
}

void Daemon::followMeshViewer(PreparedMesh& prepared) {
  MeshFollow& f = mesh_follow_;
  if (f.timer >= 0) loop_->removeTimer(f.timer);
  const uint64_t generation = f.generation + 1;
  f = MeshFollow{};
  f.generation = generation;
  f.views = std::move(prepared.views);
  f.eye = prepared.eye;
  json& viewer = keystone_rt_.mesh_info["mesh"]["viewer"];
  if (viewer.value("source", "") == "tracker") f.tracker = viewer.value("tracker", "");
  keystone_rt_.mesh_info["mesh"]["view_updates"] = 0;
  // The output's refresh rate bounds how often a view update starts.
  for (const auto& [name, view] : f.views) {
    const DeviceEntry* e = devices_.find(name);
    if (!e || !e->usable()) continue;
    uint32_t w = 0, h = 0;
    double hz = 0;
    const auto& raw = e->device.raw();
    if (raw.ops.output->get_mode(raw.self, &w, &h, &hz) == PROCAM_OK && hz > 0) {
      f.frame_period = std::chrono::nanoseconds(static_cast<int64_t>(1e9 / hz));
    }
    break;
  }
}

void Daemon::onMeshViewerSample() {
  MeshFollow& f = mesh_follow_;
  // Another content replaced the mesh; a frame in flight or a pending start looks again
  // once it is done.
  if (keystone_rt_.meshes.empty() || f.tracker.empty() || f.in_flight || f.timer >= 0) return;
  auto latest = trackers_.latest.find(f.tracker);
  if (latest == trackers_.latest.end()) return;
  const Vec3 eye = latest->second.world;
  if ((eye - f.eye).norm() <= config_.content_viewer_threshold_m) return;
  const auto now = std::chrono::steady_clock::now();
  if (const auto wait = f.last_start + f.frame_period - now; wait.count() > 0) {
    auto timer = loop_->addTimer(wait, false, [this] {
      mesh_follow_.timer = -1;
      onMeshViewerSample();
    });
    if (timer) f.timer = *timer;
    return;
  }
  // A'4x4 P_T per output: a few 4x4 products and a 4-point homography, microseconds on
  // the loop; the drawing itself runs on the compute worker (refreshOutputs).
  auto matrices = meshViewMatrices(f.views, eye);
  if (!matrices) {
    warn("3D content not drawn for the moved viewer: " + matrices.error().message);
    f.eye = eye;  // not tried again until the viewer moves on
    return;
  }
  for (const auto& [name, m] : *matrices) {
    if (auto it = keystone_rt_.meshes.find(name); it != keystone_rt_.meshes.end()) {
      it->second.planar3d = m;
    }
  }
  f.eye = eye;
  f.in_flight = true;
  f.last_start = now;
  refreshOutputs([this, generation = f.generation, eye](bool shown) {
    MeshFollow& f = mesh_follow_;
    if (f.generation != generation) return;  // another mesh was loaded meanwhile
    f.in_flight = false;
    if (shown && !keystone_rt_.meshes.empty()) {
      ++f.updates;
      json& mesh = keystone_rt_.mesh_info["mesh"];
      mesh["viewer"]["position"] = {eye.x(), eye.y(), eye.z()};
      mesh["view_updates"] = f.updates;
    }
    onMeshViewerSample();  // the viewer may have moved on while it rendered
  });
}

}  // namespace procam::daemon
