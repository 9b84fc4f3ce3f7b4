// Several projectors on one non-planar surface shown as one display for the viewer at
// the sweet spot ([Raskar02] §4.1.5, PROTOCOL.md "Several projectors on a curved
// surface"): with two or more usable outputs whose projectors the rig gives a pose and a
// surface mesh, image content is the image the static viewer ([content] viewer, or the
// rig model's) should see; every output shows its share through its own lookup warp,
// feathered in the overlaps (eq. 4.3) in linear light through its measured response
// (blend/curved_display.hpp). Made on the compute worker and kept until the content's
// size, the outputs, the rig or the eye change. A tracked viewer sees the same display
// (rectangle, weights, photometric match) from where they are: each output draws it by
// the two-pass path for the tracked eye (rig_surfaces.cpp). With [content] projection =
// "dome" the content is a dome master around the static eye (render/dome_master.hpp),
// drawn through the lookup warps for that eye alone.
#include <cmath>
#include <optional>
#include <sstream>

#include "blend/rig_tiles.hpp"
#include "core/units.hpp"
#include "daemon.hpp"
#include "json_matrix.hpp"
#include "log.hpp"
#include "render/dome_master.hpp"
#include "render/post_render_warp.hpp"

namespace procam::daemon {

using nlohmann::json;

namespace {

// [content] projection = "dome": the master's front and field of view.
struct DomeSettings {
  Vec3 front;
  double fov_deg = 180;
};

struct CurvedInput {
  std::string output;
  geom::CameraModel model;  // the rig's projector: its pinhole, and its lens for the warp
  cv::Size size;
  std::shared_ptr<const void> surface;  // holds `intersector`
  const geom::MeshIntersector* intersector = nullptr;
  Daemon::RigResponse response;
  bool own_mesh = false;  // the projector's own measured mesh, not the unified one
};

// What a display is made for: the content's size, the eye, every output's projector,
// surface and response.
std::string curvedKey(cv::Size content, const Vec3& eye, const std::vector<CurvedInput>& inputs,
                      const std::optional<DomeSettings>& dome) {
  std::ostringstream key;
  key.precision(17);
  key << content.width << 'x' << content.height << " eye " << eye.transpose();
  if (dome) key << " dome " << dome->front.transpose() << ' ' << dome->fov_deg;
  for (const auto& in : inputs) {
    key << ' ' << in.output << ' ' << in.size.width << 'x' << in.size.height << ' '
        << in.surface.get();
    const Mat34 P = in.model.projectionMatrix();
    for (int i = 0; i < 12; ++i) key << ' ' << P(i / 4, i % 4);
    const geom::Distortion& d = in.model.dist;
    key << " lens " << d.k1 << ' ' << d.k2 << ' ' << d.p1 << ' ' << d.p2 << ' ' << d.k3;
    key << in.response.key;
  }
  return key.str();
}

}  // namespace

const KeystoneRuntime::Curved* Daemon::curvedDisplay(cv::Size content, const ViewerEye& eye) {
  KeystoneRuntime& k = keystone_rt_;
  // A new rig model whose meshes are still being read: the display made for the last one
  // stays until they are (a projector's new pose with its old mesh would be solved and
  // shown for nothing).
  if (rig_surfaces_loading_) {
    const bool same = k.curved && k.curved->content == content &&
                      (k.curved->display.eye - eye.position).norm() < 1e-9;
    return same ? k.curved.get() : nullptr;
  }
  std::vector<CurvedInput> inputs;
  for (const auto& e : devices_.entries()) {
    if (e.description.family != PROCAM_FAMILY_OUTPUT || !e.usable()) continue;
    const rig::RigProjector* p = rig_.projectorForOutput(e.name);
    if (!p || !p->pose_known) continue;
    auto mode = outputMode(e.device.raw());
    if (!mode || mode->width != p->width || mode->height != p->height) continue;
    auto surface = rigSurfaceFor(p->name);
    if (!surface) continue;
    inputs.push_back({e.name, p->model(), *mode, surface, &surface->intersector, rigResponse(*p),
                      rig_surfaces_.count(p->name) > 0});
  }
  std::optional<DomeSettings> dome;
  if (config_.content_dome) {
    const auto& f = config_.content_dome_front;
    dome = DomeSettings{Vec3(f[0], f[1], f[2]), config_.content_dome_fov_deg};
  }
  // A dome master is drawn by one projector as by several; a perspective display of
  // one projector is nonPlanarSetup's own.
  if (inputs.size() < (dome ? 1u : 2u) || content.width < 1 || content.height < 1) {
    k.curved.reset();
    k.curved_key.clear();
    k.curved_error.clear();
    return nullptr;
  }
  const std::string key = curvedKey(content, eye.position, inputs, dome);
  if (key == k.curved_key) return k.curved.get();  // made, failed, or on its way
  k.curved_key = key;
  k.curved_error.clear();
  k.curved.reset();
  if (k.curving) return nullptr;  // the job running sees the new key when it ends
  k.curving = true;
  const std::string what = dome ? "dome display" : "display";
  logInfo(what + " across " + std::to_string(inputs.size()) + " outputs on the surface: solving");
  const auto solving = std::chrono::steady_clock::now();
  compute_worker_->submit(
      [this, key, content, inputs, eye, dome, what, solving] {
        auto made = std::make_shared<KeystoneRuntime::Curved>();
        std::vector<blend::SurfaceProjector> projectors;
        std::vector<std::optional<blend::ProjectorResponse>> responses;
        std::string error;
        for (const auto& in : inputs) {
          // The pinhole draws what the projector's pixels lit through the post-rendering
          // warp ([Raskar02] §4.1.3): measured from the mesh's pixels, or its lens.
          auto warp = render::projectorPostRenderWarp(
              in.model, in.own_mesh ? &in.intersector->mesh() : nullptr);
          if (!warp) {
            error = in.output + "'s post-rendering warp: " + warp.error().message;
            break;
          }
          std::shared_ptr<const render::WarpGrid> grid;
          if (*warp) grid = std::shared_ptr<const render::WarpGrid>(*warp, &(*warp)->grid);
          projectors.push_back({in.intersector, in.model.projectionMatrix(), in.size, grid});
          responses.push_back(in.response.response);
          made->outputs.push_back(in.output);
          made->surfaces.push_back(in.surface);
          made->post_warps.push_back(*warp);
        }
        Result<blend::CurvedBlend> blended = fail(ErrorCode::kInvalidInput, error);
        if (error.empty() && dome) {
          auto master = render::domeMaster(eye.position, dome->front, dome->fov_deg, content);
          blended = master ? blend::makeDomeBlend(projectors, responses, *master)
                           : Result<blend::CurvedBlend>(tl::unexpected(master.error()));
        } else if (error.empty()) {
          blended = blend::makeCurvedBlend(projectors, responses, eye.position, content);
        }
        if (blended) {
          static_cast<blend::CurvedBlend&>(*made) = std::move(*blended);
          made->weights.clear();  // the outputs take the 8-bit mask
          made->content = content;
          made->eye_source = eye.source;
        } else {
          error = blended.error().message;
        }
        const double solved_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - solving).count();
        return [this, key, made, error, what, solved_s] {
          KeystoneRuntime& k = keystone_rt_;
          k.curving = false;
          if (key == k.curved_key) {
            if (error.empty()) {
              k.curved = made;
              logInfo(what + " across " + std::to_string(made->outputs.size()) +
                      " outputs on the surface: ready (" + std::to_string(solved_s) + " s)");
            } else {
              k.curved.reset();
              k.curved_error = error;
              warn("no " + what + " across the projectors on the surface: " + error);
            }
          } else {
            k.curved_key.clear();  // made for something older: make it again
          }
          refreshOutputs();
        };
      },
      [this, key](const std::string& what) {
        KeystoneRuntime& k = keystone_rt_;
        k.curving = false;
        if (key == k.curved_key) {
          k.curved.reset();
          k.curved_error = what;
          warn("no display across the projectors on the surface: " + what);
        }
      });
  return nullptr;
}

json Daemon::curvedDisplayJson() const {
  const KeystoneRuntime& k = keystone_rt_;
  if (!k.curved) {
    if (!k.curved_error.empty()) return {{"unavailable", k.curved_error}};
    if (k.curving) return {{"state", "solving"}};
    return nullptr;
  }
  const auto& d = k.curved->display;
  json tiles = json::array();
  for (std::size_t t = 0; t < k.curved->outputs.size(); ++t) {
    json tile = {{"output", k.curved->outputs[t]},
                 {"response_gamma", k.curved->gamma[t]},
                 {"gain", k.curved->gain[t]}};
    if (const auto& w = k.curved->post_warps[t]) tile["post_warp"] = blend::postWarpJson(*w);
    tiles.push_back(std::move(tile));
  }
  json eye = k.curved->eye_source;
  eye["position"] = {d.eye.x(), d.eye.y(), d.eye.z()};
  const json blend = {{"weights", "feathered"},
                      {"response", k.curved->measured ? "measured" : "assumed gamma 2.2"},
                      {"photometric", blend::matchingJson(*k.curved)}};
  json out = {{"state", "ready"},
              {"projection", d.dome ? "dome" : "perspective"},
              {"surface", "mesh"},
              {"outputs", k.curved->outputs},
              {"content_size", {k.curved->content.width, k.curved->content.height}},
              {"viewer", eye},
              {"tiles", tiles},
              {"blend", blend}};
  if (d.dome) {
    const Vec3 front = d.dome->frame.row(1).transpose();
    out["dome"] = {{"front", {front.x(), front.y(), front.z()}},
                   // Degrees as configured, not their round trip through radians.
                   {"fov_deg", std::round(radToDeg(2 * d.dome->half_fov) * 1e9) / 1e9},
                   // The part of the master's circle the projectors draw.
                   {"coverage", d.coverage}};
    return out;
  }
  out.update(json{{"viewer_matrix", rowMajor(d.viewer)},
                  // The content on the eye's image plane z = 1 (x right, y up): its field of view.
                  {"rect_tan",
                   {{"centre", {d.rect.centre.x(), d.rect.centre.y()}},
                    {"size", {2 * d.rect.half_width, 2 * d.rect.half_height}}}},
                  {"union_area_tan2", d.union_area},
                  {"cell_tan", d.cell}});
  return out;
}

}  // namespace procam::daemon
