#include "curved_render.hpp"

#include <opencv2/imgcodecs.hpp>

#include "blend/curved_display.hpp"
#include "blend/mpcdi.hpp"
#include "blend/rig_tiles.hpp"
#include "blend/tile_frames.hpp"
#include "content/mesh_content.hpp"
#include "json_matrix.hpp"
#include "mpcdi_zip.hpp"
#include "replace_file.hpp"

namespace procam::render_cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {}  // namespace

Result<json> renderCurved(const CurvedRenderInput& in) {
  const rig::RigModel& rig = *in.rig;
  const fs::path dir = in.rig_file.parent_path();
  std::vector<const rig::RigProjector*> chosen;
  std::vector<geom::MeshIntersector> surfaces;
  std::vector<bool> own_mesh;  // the projector's own measured mesh, not the unified one
  std::vector<std::string> skipped;
  surfaces.reserve(rig.projectors.size());
  for (const rig::RigProjector& p : rig.projectors) {
    const bool asked =
        std::find(in.projectors.begin(), in.projectors.end(), p.name) != in.projectors.end();
    if (!in.projectors.empty() && !asked) continue;
    const auto mesh_it = rig.surface.meshes.find(p.name);
    const std::string file =
        mesh_it != rig.surface.meshes.end() ? mesh_it->second : rig.surface.unified_mesh;
    std::string why;
    if (!p.pose_known) why = "no calibrated pose";
    if (why.empty() && file.empty()) why = "no surface mesh";
    if (!why.empty()) {
      if (asked) return fail(ErrorCode::kNotFound, "projector '" + p.name + "': " + why);
      skipped.push_back(p.name + ": " + why);
      continue;
    }
    if (!blend::isSafeRegionId(p.name))
      return fail(
          ErrorCode::kInvalidInput,
          "projector name '" + p.name + "' cannot name a file (1-128 of A-Z a-z 0-9 . _ -)");
    if (!rig::RigSurface::isPlainFileName(file))
      return fail(ErrorCode::kInvalidInput,
                  "surface mesh '" + file + "' is not a file name beside the rig model");
    auto mesh = content::loadMeshContent(dir / file);
    if (!mesh) return fail(mesh.error().code, "surface mesh " + file + ": " + mesh.error().message);
    auto intersector = geom::MeshIntersector::build(std::move(mesh->mesh));
    if (!intersector) return tl::unexpected(intersector.error());
    surfaces.push_back(std::move(*intersector));
    own_mesh.push_back(mesh_it != rig.surface.meshes.end());
    chosen.push_back(&p);
  }
  if (chosen.empty()) {
    std::string why;
    for (const auto& s : skipped) why += "; " + s;
    return fail(ErrorCode::kNotFound, "no projector of " + in.rig_file.string() +
                                          " has a calibrated pose and a surface mesh" + why);
  }
  json eye_source = in.viewer ? "given" : "rig";
  const std::optional<Vec3> eye = in.viewer ? in.viewer : rig.viewer.position;
  if (!eye)
    return fail(ErrorCode::kNotFound,
                "a curved display is drawn for a viewer: give --viewer X,Y,Z (the rig model "
                "names none)");
  std::vector<blend::SurfaceProjector> projectors;
  std::vector<std::optional<blend::ProjectorResponse>> responses;
  std::vector<std::shared_ptr<const render::PostRenderWarp>> warps;
  for (std::size_t t = 0; t < chosen.size(); ++t) {
    // The pinhole's image moved to the pixels that lit the surface ([Raskar02] §4.1.3).
    const geom::CameraModel model = chosen[t]->model();
    auto warp = render::projectorPostRenderWarp(model, own_mesh[t] ? &surfaces[t].mesh() : nullptr);
    if (!warp) {
      return fail(warp.error().code,
                  chosen[t]->name + "'s post-rendering warp: " + warp.error().message);
    }
    std::shared_ptr<const render::WarpGrid> grid;
    if (*warp) grid = std::shared_ptr<const render::WarpGrid>(*warp, &(*warp)->grid);
    warps.push_back(*warp);
    projectors.push_back({&surfaces[t], model.projectionMatrix(),
                          cv::Size(chosen[t]->width, chosen[t]->height), grid});
    responses.push_back(blend::projectorResponse(*chosen[t]));
  }
  std::optional<render::DomeMaster> master;
  if (in.dome_front) {
    auto m = render::domeMaster(*eye, *in.dome_front, in.dome_fov_deg, in.content.size());
    if (!m) return tl::unexpected(m.error());
    master = *m;
  }
  auto made = master ? blend::makeDomeBlend(projectors, responses, *master)
                     : blend::makeCurvedBlend(projectors, responses, *eye, in.content.size());
  if (!made) return tl::unexpected(made.error());
  const blend::CurvedDisplay& d = made->display;
  json shares = json::array();
  for (std::size_t t = 0; t < chosen.size(); ++t) {
    const std::string file = chosen[t]->name + ".png";
    if (!in.out.empty()) {
      auto frame = blend::curvedFrame(in.content, *made, t, {in.bit_depth, in.geometry_only});
      if (!frame) return tl::unexpected(frame.error());
      std::vector<uint8_t> png;
      if (!cv::imencode(".png", *frame, png))
        return fail(ErrorCode::kIo, "cannot encode " + chosen[t]->name + "'s frame");
      if (auto ok = replaceFileWith(in.out / file, std::string(png.begin(), png.end())); !ok)
        return tl::unexpected(ok.error());
    }
    shares.push_back({{"name", chosen[t]->name},
                      {"output", chosen[t]->output},
                      {"file", file},
                      {"size", {chosen[t]->width, chosen[t]->height}},
                      {"path", "lookup-warp"},
                      {"response_gamma", made->gamma[t]},
                      {"gain", made->gain[t]}});
    if (warps[t]) shares.back()["post_warp"] = blend::postWarpJson(*warps[t]);
  }
  if (!in.mpcdi.empty()) {
    std::vector<std::string> names;
    for (const auto* p : chosen) names.push_back(p->name);
    auto package = blend::mpcdi2d(*made, names, in.content.size(), in.date);
    if (!package) return tl::unexpected(package.error());
    if (auto ok = writeMpcdiZip(in.mpcdi, *package); !ok) return tl::unexpected(ok.error());
  }
  json display = {{"projection", master ? "dome" : "perspective"},
                  {"surface", "mesh"},
                  {"viewer", {{"position", daemon::vectorJson(*eye)}, {"source", eye_source}}}};
  if (master) {
    display["dome"] = {{"front", daemon::vectorJson(Vec3(master->frame.row(1).transpose()))},
                       {"fov_deg", in.dome_fov_deg},
                       {"coverage", d.coverage}};
  } else {
    json viewer_matrix = json::array();
    for (int i = 0; i < 12; ++i) viewer_matrix.push_back(d.viewer(i / 4, i % 4));
    display["viewer_matrix"] = viewer_matrix;
    display["rect_tan"] = {{"centre", {d.rect.centre.x(), d.rect.centre.y()}},
                           {"size", {2 * d.rect.half_width, 2 * d.rect.half_height}}};
    display["union_area_tan2"] = d.union_area;
  }
  json doc = {{"display", display},
              {"blend",
               {{"weights", in.geometry_only ? "none" : "feathered"},
                {"response", in.geometry_only ? "none"
                             : made->measured ? "measured"
                                              : "assumed gamma 2.2"},
                {"photometric",
                 in.geometry_only ? json{{"matching", "none"}} : blend::matchingJson(*made)}}},
              {"projectors", shares}};
  if (!skipped.empty()) doc["skipped"] = skipped;
  return doc;
}

}  // namespace procam::render_cli
