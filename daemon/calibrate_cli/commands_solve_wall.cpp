// solve-wall: route (b′) on a planar wall from cameras at several positions
// (calibration/wall_views_route.hpp), every projector into one rig.json.
#include <cmath>
#include <sstream>

#include "calibration/wall_views_route.hpp"
#include "cli_files.hpp"
#include "commands.hpp"
#include "rig/rig_model.hpp"

namespace procam::cli {
namespace {

// "a,b,c,d": a x + b y + c z + d = 0 in the cameras' world frame, metres.
Result<geom::Plane> planeOption(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    auto x = toDouble(part, "--plane");
    if (!x) return tl::unexpected(x.error());
    v.push_back(*x);
  }
  auto plane = v.size() == 4 ? geom::planeFromCoefficients(v[0], v[1], v[2], v[3]) : std::nullopt;
  if (!plane)
    return fail(ErrorCode::kInvalidInput,
                kCommandLine +
                    "--plane takes a,b,c,d (a x + b y + c z + d = 0, metres) with a "
                    "non-zero normal");
  return *plane;
}

}  // namespace

Result<void> runSolveWall(const Arguments& a) {
  if (auto ok = a.only({"cameras", "out", "plane", "reference", "step"}); !ok) return ok;
  auto cameras_file = a.one("cameras");
  auto out = a.one("out");
  auto plane_text = a.one("plane");
  for (const auto* r : {&cameras_file, &out, &plane_text})
    if (!*r) return tl::unexpected(r->error());
  auto plane = planeOption(*plane_text);
  if (!plane) return tl::unexpected(plane.error());
  auto step = stepOption(a);
  if (!step) return tl::unexpected(step.error());
  if (a.groups().empty() || a.groups().size() > 64)
    return fail(
        ErrorCode::kInvalidInput,
        kCommandLine + "give 1 to 64 --projector NAME --patterns DIR --captures ... groups");
  auto cameras = readCameras(*cameras_file);
  if (!cameras) return tl::unexpected(cameras.error());
  std::size_t reference = 0;
  if (auto name = a.optional("reference")) {
    reference = cameras->size();
    for (std::size_t c = 0; c < cameras->size(); ++c)
      if ((*cameras)[c].name == *name) reference = c;
    if (reference == cameras->size())
      return fail(ErrorCode::kInvalidInput,
                  kCommandLine + "--reference " + *name + ": no such camera in " + *cameras_file);
  }

  std::vector<std::string> names;
  std::vector<std::pair<int, int>> sizes;
  std::vector<calib::WallNodes> nodes;
  const calib::WallViewsOptions options{.nodes = {.step = *step}, .reference_camera = reference};
  for (const Arguments& g : a.groups()) {
    if (auto ok = g.only({"projector", "patterns", "captures"}); !ok) return ok;
    auto name = g.one("projector");
    auto patterns = g.one("patterns");
    for (const auto* r : {&name, &patterns})
      if (!*r) return tl::unexpected(r->error());
    if (!isFileSafeName(*name))
      return fail(ErrorCode::kInvalidInput,
                  kCommandLine + "--projector '" + *name + "': 1-128 of A-Z a-z 0-9 . _ -");
    if (std::find(names.begin(), names.end(), *name) != names.end())
      return fail(ErrorCode::kInvalidInput, kCommandLine + "--projector " + *name + " given twice");
    const auto& dirs = g.all("captures");
    if (dirs.empty() || dirs.size() > cameras->size())
      return fail(ErrorCode::kInvalidInput, kCommandLine + "--projector " + *name +
                                                ": give one --captures directory per "
                                                "camera of " +
                                                *cameras_file + " (at most " +
                                                std::to_string(cameras->size()) +
                                                "; - for one that did not "
                                                "film it)");
    auto set = readSequence(*patterns);
    if (!set) return tl::unexpected(set.error());
    const std::size_t p = names.size();
    names.push_back(*name);
    sizes.emplace_back(set->options.width, set->options.height);
    for (std::size_t c = 0; c < dirs.size(); ++c) {
      if (dirs[c] == "-") continue;
      const rig::NamedCamera& camera = (*cameras)[c];
      auto decoded = decodeDir(*set, dirs[c], c, dirs.size());
      // A camera at one position sees only part of the wall: one that saw nothing of
      // this projector is no failure.
      if (!decoded && decoded.error().code == ErrorCode::kTooFewPoints) {
        progress("  camera " + camera.name + " does not see " + *name);
        continue;
      }
      if (!decoded) return tl::unexpected(decoded.error());
      const calib::DecodedView view{camera.name, camera.model, std::move(*decoded)};
      auto seen = calib::wallSighting(*set, view, options.nodes);
      if (!seen) return tl::unexpected(seen.error());
      if (!seen->nodes) {
        progress("  camera " + camera.name + " left out for " + *name + ": " + seen->why);
        continue;
      }
      progress("  camera " + camera.name + " sees " +
               std::to_string(seen->nodes->projector.size()) + " nodes of " + *name);
      nodes.push_back({p, c, std::move(*seen->nodes)});
    }
  }
  const rig::NamedCamera& ref = (*cameras)[reference];
  progress("solving " + std::to_string(names.size()) + " projectors through " +
           std::to_string(cameras->size()) + " cameras (reference " + ref.name + ")");
  calib::WallViewsOptions named = options;
  for (const rig::NamedCamera& c : *cameras) named.camera_names.push_back("camera " + c.name);
  for (const std::string& n : names) named.projector_names.push_back("projector " + n);
  auto solved =
      calib::solveWallViews(sizes, cameras->size(), nodes, ref.model, ref.name, *plane, named);
  if (!solved) return tl::unexpected(solved.error());
  progress("homography tree: " + std::to_string(solved->tree.links) + " camera-projector links, " +
           std::to_string(solved->tree.matches) + " nodes, residual " +
           std::to_string(solved->tree.rms_px) + " camera px (chained alone " +
           std::to_string(solved->tree.chain_rms_px) + ")");

  rig::RigModel model;
  for (const rig::NamedCamera& c : *cameras) {
    rig::RigCamera camera;
    camera.name = c.name;
    camera.model = c.model;
    camera.rms_px = c.rms_px;
    model.cameras.push_back(camera);
  }
  std::string how =
      "structured light, route (b′): cameras at several positions, " + ref.name + " (reference)";
  for (const rig::NamedCamera& c : *cameras)
    if (c.name != ref.name) how += ", " + c.name;
  for (std::size_t p = 0; p < names.size(); ++p) {
    rig::RigProjector projector;
    projector.name = names[p];
    projector.width = sizes[p].first;
    projector.height = sizes[p].second;
    projector.intrinsics_known = false;
    projector.pose_known = false;
    projector.plane_homography = solved->projector_to_plane[p];
    projector.rms_px = solved->projectors[p].rms_projector_px;
    projector.points = static_cast<long>(solved->projectors[p].nodes);
    projector.calibrated = {how, ""};
    progress(names[p] + ": " + std::to_string(solved->projectors[p].cameras) + " cameras, " +
             std::to_string(solved->projectors[p].nodes) + " nodes, " +
             std::to_string(solved->projectors[p].rms_projector_px) + " projector px RMS");
    model.projectors.push_back(std::move(projector));
  }
  model.surface.plane = *plane;
  progress("writing " + *out);
  return writeText(*out, rig::rigToJson(model).dump(2) + "\n");
}

}  // namespace procam::cli
