// camera, stereo, solve (route a), solve-planes (route b), solve-fiducials (route c).
#include <algorithm>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "calibration/camera_calibration.hpp"
#include "calibration/projector_calibration.hpp"
#include "calibration/stereo_route.hpp"
#include "cli_files.hpp"
#include "commands.hpp"
#include "surface/mesh_unification.hpp"
#include "surface/projector_samples.hpp"
#include "surface/surface_model.hpp"

namespace procam::cli {
namespace {

template <class T>
Result<void> asVoid(const Result<T>& r) {
  if (!r) return tl::unexpected(r.error());
  return {};
}

Result<std::vector<calib::BoardView>> detectAll(const calib::BoardSpec& spec, const fs::path& dir,
                                                cv::Size& size) {
  auto files = listImages(dir);
  if (!files) return tl::unexpected(files.error());
  std::vector<calib::BoardView> views;
  for (std::size_t i = 0; i < files->size(); ++i) {
    const fs::path& f = (*files)[i];
    cv::Mat image = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
    if (image.empty()) return fail(ErrorCode::kIo, "cannot read " + f.string());
    if (size.area() > 0 && image.size() != size)
      return fail(ErrorCode::kInvalidInput,
                  f.string() + " has a different size from the first image");
    size = image.size();
    auto v = calib::detectBoard(spec, image);
    progress("board view " + std::to_string(i + 1) + "/" + std::to_string(files->size()) + " " +
             f.filename().string() + ": " +
             (v ? std::to_string(v->image.size()) + " points" : v.error().message));
    if (v) views.push_back(std::move(*v));
  }
  return views;
}

// Route (a) from the captures of the first two cameras (the i-th directory the i-th's).
Result<calib::StereoRouteResult> stereoRoute(const sl::PatternSet& set,
                                             const std::vector<std::string>& dirs,
                                             const std::vector<rig::NamedCamera>& cameras,
                                             int step) {
  calib::DecodedView views[2];
  for (std::size_t i = 0; i < 2; ++i) {
    auto d = decodeDir(set, dirs[i], i, 2);
    if (!d) return tl::unexpected(d.error());
    views[i] = {cameras[i].name, cameras[i].model, std::move(*d)};
  }
  return calib::solveStereoRoute(set, views[0], views[1], step);
}

Result<void> writeRig(const fs::path& out, const std::vector<NamedCamera>& cameras,
                      const NamedProjector& projector, const nlohmann::json& surface) {
  const nlohmann::json j = rig::rigJson(cameras, projector, surface);
  progress("projector '" + projector.name + "': fx " + std::to_string(projector.calibration.K.fx) +
           ", fy " + std::to_string(projector.calibration.K.fy) + ", reprojection RMS " +
           std::to_string(projector.calibration.rms_px) + " px; writing " + out.string());
  return writeText(out, j.dump(2) + "\n");
}

}  // namespace

Result<void> runCamera(const Arguments& a) {
  if (auto ok = a.only({"images", "board", "out", "name"}); !ok) return ok;
  auto images = a.one("images");
  auto board = a.one("board").and_then(calib::parseBoard);
  auto out = a.one("out");
  if (!images) return asVoid(images);
  if (!board) return asVoid(board);
  if (!out) return asVoid(out);
  cv::Size size;
  auto views = detectAll(*board, *images, size);
  if (!views) return asVoid(views);
  auto cal = calib::calibrateCamera(*views, size.width, size.height);
  if (!cal) return asVoid(cal);
  NamedCamera c{a.optional("name").value_or("camera"), cal->camera, cal->rms_px};
  progress("fx " + std::to_string(c.model.K.fx) + ", fy " + std::to_string(c.model.K.fy) +
           ", reprojection RMS " + std::to_string(cal->rms_px) + " px over " +
           std::to_string(views->size()) + " views");
  nlohmann::json j = {{"cameras", nlohmann::json::array({cameraJson(c)})}};
  return writeText(*out, j.dump(2) + "\n");
}

Result<void> runStereo(const Arguments& a) {
  if (auto ok = a.only({"images", "board", "out", "names"}); !ok) return ok;
  const auto& dirs = a.all("images");
  auto board = a.one("board").and_then(calib::parseBoard);
  auto out = a.one("out");
  if (dirs.size() != 2)
    return fail(ErrorCode::kInvalidInput, "--images takes two directories (same file names)");
  if (!board) return asVoid(board);
  if (!out) return asVoid(out);
  // Keep only file names present in both directories and detected in both.
  auto fa = listImages(dirs[0]);
  if (!fa) return asVoid(fa);
  std::vector<calib::BoardView> va, vb;
  cv::Size size;
  for (const fs::path& f : *fa) {
    const fs::path g = fs::path(dirs[1]) / f.filename();
    if (!fs::exists(g)) continue;
    cv::Mat ia = cv::imread(f.string(), cv::IMREAD_UNCHANGED),
            ib = cv::imread(g.string(), cv::IMREAD_UNCHANGED);
    if (ia.empty() || ib.empty())
      return fail(ErrorCode::kIo, "cannot read " + f.filename().string());
    size = ia.size();
    auto da = calib::detectBoard(*board, ia), db = calib::detectBoard(*board, ib);
    const bool both = da && db && da->board == db->board;
    progress("view " + f.filename().string() + (both ? ": seen by both cameras" : ": skipped"));
    if (both) va.push_back(*da), vb.push_back(*db);
  }
  auto ca = calib::calibrateCamera(va, size.width, size.height);
  if (!ca) return asVoid(ca);
  auto cb = calib::calibrateCamera(vb, size.width, size.height);
  if (!cb) return asVoid(cb);
  auto s = calib::calibrateStereo(ca->camera, va, cb->camera, vb);
  if (!s) return asVoid(s);
  const auto& names = a.all("names");
  NamedCamera first{names.size() == 2 ? names[0] : "cam0", ca->camera, ca->rms_px};
  NamedCamera second{names.size() == 2 ? names[1] : "cam1", cb->camera, cb->rms_px};
  second.model.pose = s->b_from_a;  // world = first camera's frame
  progress("baseline " + std::to_string(s->b_from_a.center().norm()) + " m, stereo RMS " +
           std::to_string(s->rms_px) + " px");
  nlohmann::json j = {{"cameras", nlohmann::json::array({cameraJson(first), cameraJson(second)})}};
  return writeText(*out, j.dump(2) + "\n");
}

// Route (a) for several projectors, one `--projector NAME --patterns DIR --captures A B`
// group each, into one rig.json: every projector in the cameras' world frame, its mesh
// beside rig.json as surface-NAME.ply (rig.json `surface.meshes`).
Result<void> runSolveProjectors(const Arguments& a) {
  if (auto ok = a.only({"cameras", "out", "step"}); !ok) return ok;
  auto cameras_file = a.one("cameras");
  auto out = a.one("out");
  auto step = stepOption(a);
  for (const auto* r : {&cameras_file, &out})
    if (!*r) return asVoid(*r);
  if (!step) return asVoid(step);
  if (a.groups().size() > 64)
    return fail(ErrorCode::kInvalidInput, kCommandLine + "at most 64 --projector groups");
  auto cameras = readCameras(*cameras_file);
  if (!cameras) return asVoid(cameras);
  if (cameras->size() < 2)
    return fail(ErrorCode::kInvalidInput, *cameras_file + " holds one camera; solve needs two");
  nlohmann::json doc;
  nlohmann::json meshes = nlohmann::json::object();
  std::vector<std::string> plies;             // file per projector
  std::vector<surface::UnifyProjector> made;  // mesh per projector
  for (const Arguments& g : a.groups()) {
    if (auto ok = g.only({"projector", "patterns", "captures"}); !ok) return ok;
    auto name = g.one("projector");
    auto patterns = g.one("patterns");
    for (const auto* r : {&name, &patterns})
      if (!*r) return asVoid(*r);
    // The name becomes a file name beside rig.json.
    if (!isFileSafeName(*name))
      return fail(ErrorCode::kInvalidInput,
                  kCommandLine + "--projector '" + *name + "': 1-128 of A-Z a-z 0-9 . _ -");
    if (meshes.contains(*name))
      return fail(ErrorCode::kInvalidInput, kCommandLine + "--projector " + *name + " given twice");
    const auto& dirs = g.all("captures");
    if (dirs.size() != 2)
      return fail(ErrorCode::kInvalidInput,
                  kCommandLine + "--projector " + *name + ": give --captures CAPDIR CAPDIR2");
    auto set = readSequence(*patterns);
    if (!set) return asVoid(set);
    auto route = stereoRoute(*set, dirs, *cameras, *step);
    if (!route) {
      return fail(route.error().code, "projector " + *name + ": " + route.error().message);
    }
    if (route->surface.planar)
      return fail(ErrorCode::kCoplanar,
                  "projector " + *name +
                      ": the surface it lights is planar; several projectors on one wall are "
                      "calibrated with one camera and the wall's plane (procamd calibrate, "
                      "route b')");
    progress(*name + ": triangulated " + std::to_string(route->triangulated) +
             " projector nodes, " + std::to_string(route->consistent) +
             " consistent with the projector");
    const NamedProjector p{*name, set->options.width, set->options.height, route->projector};
    if (doc.is_null()) {
      doc = rig::rigJson(*cameras, p, nullptr);
    } else {
      doc["projectors"].push_back(rig::projectorJson(p));
    }
    const std::string file = "surface-" + *name + ".ply";
    meshes[*name] = file;
    plies.push_back((fs::path(*out).parent_path() / file).string());
    geom::CameraModel fitted;
    fitted.K = route->projector.K;
    fitted.pose = route->projector.pose;
    made.push_back({std::move(route->surface.mesh), fitted.projectionMatrix(),
                    cv::Size(set->options.width, set->options.height)});
  }
  // Where the projectors' meshes overlap they are unified ([Raskar02] eq. 4.4), as the
  // daemon's calibrate does.
  if (made.size() > 1) {
    auto unified = surface::unifyMeshes(made);
    if (!unified) return asVoid(unified);
    char line[200];
    std::snprintf(line, sizeof line,
                  "meshes unified: %d of %d vertices shared, %.3f mm apart RMS before, %.3f mm "
                  "after",
                  unified->shared, unified->vertices, 1000 * unified->gap_rms_m,
                  1000 * unified->gap_after_rms_m);
    progress(line);
  }
  // Meshes first, rig.json last: a rig.json never names a mesh that is not written.
  for (std::size_t k = 0; k < plies.size(); ++k) {
    progress("mesh -> " + plies[k]);
    if (auto w = writeText(plies[k], surface::toPly(made[k].mesh)); !w) return w;
  }
  doc["surface"] = {{"meshes", meshes}};
  return writeText(*out, doc.dump(2) + "\n");
}

Result<void> runSolve(const Arguments& a) {
  if (!a.groups().empty()) return runSolveProjectors(a);
  if (auto ok = a.only({"patterns", "captures", "cameras", "out", "surface-out", "step", "name"});
      !ok)
    return ok;
  auto patterns = a.one("patterns");
  auto cameras_file = a.one("cameras");
  auto out = a.one("out");
  auto step = stepOption(a);
  for (const auto* r : {&patterns, &cameras_file, &out})
    if (!*r) return asVoid(*r);
  if (!step) return asVoid(step);
  const auto& dirs = a.all("captures");
  if (dirs.size() != 2)
    return fail(ErrorCode::kInvalidInput,
                "solve triangulates with two calibrated cameras: give --captures CAPDIR CAPDIR2 "
                "(for one camera and a plane seen at several orientations use solve-planes)");
  auto cameras = readCameras(*cameras_file);
  if (!cameras) return asVoid(cameras);
  if (cameras->size() < 2)
    return fail(ErrorCode::kInvalidInput, *cameras_file + " holds one camera; solve needs two");
  auto set = readSequence(*patterns);
  if (!set) return asVoid(set);
  auto route = stereoRoute(*set, dirs, *cameras, *step);
  if (!route && route.error().code == ErrorCode::kCoplanar)
    return fail(ErrorCode::kCoplanar, route.error().message +
                                          " (procam-calibrate solve-planes, with captures of "
                                          "the plane at two or more orientations)");
  if (!route) return asVoid(route);
  progress("triangulated " + std::to_string(route->triangulated) + " projector nodes (every " +
           std::to_string(*step) + " px), " + std::to_string(route->consistent) +
           " consistent with the projector");
  const surface::SurfaceModel& model = route->surface;
  std::string ply;
  if (!model.planar) {
    ply = a.optional("surface-out").value_or(fs::path(*out).replace_extension(".ply").string());
    progress("surface is not planar (" + std::to_string(model.inlier_fraction * 100) +
             "% on the best plane): mesh of " + std::to_string(model.mesh.faces.size()) +
             " triangles -> " + ply);
    if (auto w = writeText(ply, surface::toPly(model.mesh)); !w) return w;
  }
  NamedProjector p{a.optional("name").value_or("projector"), set->options.width,
                   set->options.height, route->projector};
  return writeRig(*out, *cameras, p, rig::surfaceJson(model, ply));
}

Result<void> runSolvePlanes(const Arguments& a) {
  if (auto ok = a.only({"patterns", "captures", "cameras", "camera", "out", "plane-distance",
                        "principal-x", "step", "name"});
      !ok)
    return ok;
  auto patterns = a.one("patterns");
  auto cameras_file = a.one("cameras");
  auto out = a.one("out");
  auto step = stepOption(a);
  for (const auto* r : {&patterns, &cameras_file, &out})
    if (!*r) return asVoid(*r);
  if (!step) return asVoid(step);
  const auto& dirs = a.all("captures");
  if (dirs.size() < 2)
    return fail(ErrorCode::kInvalidInput,
                "solve-planes needs --captures with one directory per plane orientation (>= 2)");
  auto cameras = readCameras(*cameras_file);
  if (!cameras) return asVoid(cameras);
  std::size_t ci = 0;
  if (auto name = a.optional("camera")) {
    ci = cameras->size();
    for (std::size_t i = 0; i < cameras->size(); ++i)
      if ((*cameras)[i].name == *name) ci = i;
    if (ci == cameras->size()) return fail(ErrorCode::kNotFound, "no camera named '" + *name + "'");
  }
  auto set = readSequence(*patterns);
  if (!set) return asVoid(set);
  calib::PlaneRouteOptions o;
  o.projector_width = set->options.width;
  o.projector_height = set->options.height;
  if (auto d = a.optional("plane-distance")) {
    auto v = toDouble(*d, "--plane-distance");
    if (!v) return asVoid(v);
    o.first_plane_distance = *v;
  }
  if (auto x = a.optional("principal-x")) {
    auto v = toDouble(*x, "--principal-x");
    if (!v) return asVoid(v);
    o.principal_x = *v;
  }
  std::vector<calib::PlaneView> views;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    auto d = decodeDir(*set, dirs[i], i, dirs.size());
    if (!d) return asVoid(d);
    auto s = surface::sampleProjectorGrid(*d, o.projector_width, o.projector_height,
                                          {.step = *step, .radius = calib::sampleRadius(*set)});
    if (!s) return asVoid(s);
    views.push_back({s->camera, s->projector});
  }
  progress("solving route (b) over " + std::to_string(views.size()) + " plane orientations");
  auto projector = calib::calibrateProjectorFromPlanes((*cameras)[ci].model, views, o);
  if (!projector) return asVoid(projector);
  NamedProjector p{a.optional("name").value_or("projector"), o.projector_width, o.projector_height,
                   *projector};
  return writeRig(*out, *cameras, p, nullptr);
}

Result<void> runSolveFiducials(const Arguments& a) {
  if (auto ok = a.only({"fiducials", "projector", "cameras", "out", "name"}); !ok) return ok;
  auto file = a.one("fiducials");
  auto size =
      a.one("projector").and_then([](const std::string& s) { return toSize(s, "--projector"); });
  auto out = a.one("out");
  if (!file) return asVoid(file);
  if (!size) return asVoid(size);
  if (!out) return asVoid(out);
  auto j = readJson(*file);
  if (!j) return asVoid(j);
  Points3 world;
  Points2 pixels;
  try {
    for (const auto& p : j->at("points")) {
      const auto& w = p.at("world");
      const auto& q = p.at("projector");
      world.emplace_back(w.at(0).get<double>(), w.at(1).get<double>(), w.at(2).get<double>());
      pixels.emplace_back(q.at(0).get<double>(), q.at(1).get<double>());
    }
  } catch (const nlohmann::json::exception& e) {
    return fail(
        ErrorCode::kParse,
        *file + ": expected {\"points\": [{\"world\": [x, y, z], \"projector\": [u, v]}, ...]}: " +
            e.what());
  }
  progress(std::to_string(world.size()) + " fiducials");
  auto projector = calib::calibrateProjectorFromFiducials(world, pixels);
  if (!projector) return asVoid(projector);
  std::vector<NamedCamera> cameras;
  if (auto c = a.optional("cameras")) {
    auto read = readCameras(*c);
    if (!read) return asVoid(read);
    cameras = std::move(*read);
  }
  NamedProjector p{a.optional("name").value_or("projector"), size->first, size->second, *projector};
  return writeRig(*out, cameras, p, nullptr);
}

}  // namespace procam::cli
