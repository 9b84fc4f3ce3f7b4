// The rig's display surfaces as the renderer needs them: the per-projector mesh files of
// rig.json read on the I/O worker, and the render setup of image content on a non-planar
// surface for the viewer ([Raskar02] §3.2.3 two-pass for a tracked viewer, §4.1.5 lookup
// warp for a static one; render/viewer_view.hpp).
#include <filesystem>

#include "content/mesh_content.hpp"
#include "daemon.hpp"
#include "log.hpp"
#include "render/viewer_view.hpp"

namespace procam::daemon {

void Daemon::loadRigSurfaces() {
  const uint64_t generation = ++rig_generation_;
  std::map<std::string, std::string> files = rig_.surface.meshes;
  if (!rig_.surface.unified_mesh.empty()) files[""] = rig_.surface.unified_mesh;
  if (files.empty()) {
    rig_surfaces_.clear();
    rig_surfaces_loading_ = false;
    return;
  }
  rig_surfaces_loading_ = true;
  io_worker_->submit(
      [this, generation, files, dir = options_.state_dir] {
        auto loaded =
            std::make_shared<std::map<std::string, std::shared_ptr<const RigSurfaceMesh>>>();
        auto problems = std::make_shared<std::vector<std::string>>();
        for (const auto& [projector, file] : files) {
          if (!rig::RigSurface::isPlainFileName(file)) {
            problems->push_back("surface mesh '" + file +
                                "' is not a file name in the state directory");
            continue;
          }
          auto mesh = content::loadMeshContent(std::filesystem::path(dir) / file);
          if (!mesh) {
            problems->push_back("surface mesh " + file + ": " + mesh.error().message);
            continue;
          }
          render::SurfaceMesh surface;
          surface.vertices = mesh->mesh.vertices;
          for (const auto& f : mesh->mesh.faces) surface.triangles.push_back({f.x(), f.y(), f.z()});
          auto intersector = geom::MeshIntersector::build(std::move(mesh->mesh));
          if (!intersector) {
            problems->push_back("surface mesh " + file + ": " + intersector.error().message);
            continue;
          }
          (*loaded)[projector] = std::make_shared<const RigSurfaceMesh>(
              RigSurfaceMesh{std::move(*intersector), std::move(surface)});
        }
        return [this, generation, loaded, problems] {
          for (const auto& p : *problems) warn(p);
          if (generation != rig_generation_) return;  // the rig changed again meanwhile
          rig_surfaces_ = std::move(*loaded);
          rig_surfaces_loading_ = false;
          refreshOutputs();
        };
      },
      [this, generation](const std::string& what) {
        warn("the rig's surface meshes were not loaded: " + what);
        if (generation == rig_generation_) rig_surfaces_loading_ = false;
      });
}

std::optional<Daemon::ViewerEye> Daemon::staticEye() const {
  if (const auto& c = config_.content_viewer) {
    return ViewerEye{Vec3((*c)[0], (*c)[1], (*c)[2]), {{"source", "config"}}};
  }
  if (rig_.viewer.position) return ViewerEye{*rig_.viewer.position, {{"source", "rig"}}};
  return std::nullopt;
}

std::optional<Daemon::ViewerEye> Daemon::viewerEye() const {
  if (const nlohmann::json v = viewerJson(); v.is_object() && v["position"].is_array()) {
    return ViewerEye{Vec3(v["position"][0].get<double>(), v["position"][1].get<double>(),
                          v["position"][2].get<double>()),
                     {{"source", "tracker"}, {"tracker", v.value("tracker", "")}}};
  }
  return staticEye();
}

std::pair<std::optional<Vec3>, nlohmann::json> Daemon::contentEye() const {
  const auto viewer = viewerEye();
  if (!viewer) return {std::nullopt, nlohmann::json()};
  return {viewer->position, viewer->source};
}

std::shared_ptr<const Daemon::RigSurfaceMesh> Daemon::rigSurfaceFor(
    const std::string& projector) const {
  auto s = rig_surfaces_.find(projector);
  if (s == rig_surfaces_.end()) s = rig_surfaces_.find("");  // the unified mesh
  return s == rig_surfaces_.end() ? nullptr : s->second;
}

Result<std::shared_ptr<const render::RenderSetup>> Daemon::nonPlanarSetup(
    const std::string& output, const render::SceneTraits& traits, cv::Size mode, cv::Size content,
    const Mat34* fixed_viewer, int* share) {
  if (share) *share = -1;
  const rig::RigProjector* p = rig_.projectorForOutput(output);
  if (!p || !p->pose_known) return fail(ErrorCode::kNotFound, "the projector has no pose");
  if (p->width != mode.width || p->height != mode.height) {
    return fail(ErrorCode::kNotFound, "the output's mode differs from the calibrated projector's");
  }
  const auto surface = rigSurfaceFor(p->name);
  if (!surface) return fail(ErrorCode::kNotFound, "the surface mesh is not loaded");
  // The eye of the viewer kind the path is chosen for: a tracker's when tracked, else the
  // configured or the rig's sweet spot. Content drawn for a fixed matrix needs none.
  // A dome master is made for the static eye: a tracker does not move it.
  const bool tracked =
      traits.viewer == render::ViewerKind::kTracked && !fixed_viewer && !config_.content_dome;
  std::optional<Vec3> eye;
  if (fixed_viewer) {
    eye = Vec3::Zero();
  } else if (auto e = tracked ? viewerEye() : staticEye()) {
    eye = e->position;
  }
  if (!eye) {
    return fail(ErrorCode::kNotFound,
                "no viewer ([content] viewer, a tracker or the rig model's viewer)");
  }
  const Mat34 P = p->model().projectionMatrix();
  auto& st = keystone_rt_.output_state[output];
  const std::optional<Mat34> fixed =
      fixed_viewer ? std::optional<Mat34>(*fixed_viewer) : std::nullopt;
  // Several projectors: this output's share of one display, made for the static viewer
  // (the sweet spot). A tracked viewer sees the same display from where they are: the
  // same content rectangle and blend, each output drawing it by the two-pass path for
  // the tracked eye (the eq. 4.3 weights and the photometric match are properties of
  // the surface, not of the eye).
  std::shared_ptr<const KeystoneRuntime::Curved> curved;
  int index = -1;
  if (!fixed) {
    if (auto e = staticEye(); e && curvedDisplay(content, *e)) {
      index = keystone_rt_.curved->index(output);
      if (index >= 0) curved = keystone_rt_.curved;
    }
  }
  if (share) *share = index;
  if (!fixed && !curved && config_.content_dome) {
    const std::string& error = keystone_rt_.curved_error;
    return fail(ErrorCode::kNotFound,
                error.empty() ? "the dome display is being solved" : "no dome display: " + error);
  }
  if (st.np_setup && st.np_surface == surface && st.np_eye == *eye && st.np_content == content &&
      st.np_projector == P && st.np_tracked == tracked && st.np_fixed == fixed &&
      st.np_curved == curved) {
    return st.np_setup;
  }
  // The setup made, and what it was made for.
  auto remember = [&](render::RenderSetup setup) {
    st.np_setup = std::make_shared<const render::RenderSetup>(std::move(setup));
    st.np_surface = surface;
    st.np_eye = *eye;
    st.np_content = content;
    st.np_projector = P;
    st.np_tracked = tracked;
    st.np_fixed = fixed;
    st.np_curved = curved;
    return st.np_setup;
  };
  if (curved) {
    render::RenderSetup setup;
    setup.output_size = mode;
    setup.content_size = content;
    if (tracked) {
      setup.path = render::RenderPath::kTwoPassMesh;
      setup.surface = surface->mesh;
      setup.projector = P;
      setup.viewer =
          render::contentViewMatrix(curved->display.rotation, *eye, curved->display.rect, content);
      // What the pinhole drew, moved to the pixels that lit it ([Raskar02] §4.1.3).
      if (const auto& warp = curved->post_warps[index]) setup.post_warp = warp->grid;
    } else {
      setup.path = render::RenderPath::kLookupWarp;
      setup.lookup = curved->display.lookup[index];
      setup.viewer = curved->display.viewer;
    }
    // Eq. 4.3 weights in linear light, through the projector's response, matched per
    // pixel or by a brightness gain ([Raskar02] §4.1.2, [Majumder05]).
    setup.final_stage.alpha = curved->alpha[index];
    setup.final_stage.weight_lut = curved->weight_lut[index];
    return remember(std::move(setup));
  }
  auto V = fixed ? Result<Mat34>(*fixed)
                 : render::viewerContentMatrix(surface->intersector, P, mode, *eye, content);
  if (!V) return tl::unexpected(V.error());
  render::RenderSetup setup;
  setup.output_size = mode;
  setup.content_size = content;
  if (tracked) {
    setup.path = render::RenderPath::kTwoPassMesh;
    setup.surface = surface->mesh;
    setup.projector = P;
    setup.viewer = *V;
  } else {
    setup.path = render::RenderPath::kLookupWarp;
    auto grid = render::lookupGridForViewer(surface->intersector, P, mode, *V);
    if (!grid) return tl::unexpected(grid.error());
    setup.lookup = std::move(*grid);
    setup.viewer = *V;  // reported in status; the grid is what is drawn
  }
  return remember(std::move(setup));
}

}  // namespace procam::daemon
