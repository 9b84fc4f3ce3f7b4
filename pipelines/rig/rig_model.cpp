#include "rig/rig_model.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace procam::rig {

using nlohmann::json;

namespace {

// Bounds a hostile document: a rig has a handful of devices.
constexpr size_t kMaxDevices = 64;

Result<std::vector<double>> numbers(const json& j, const char* key, size_t n,
                                    const std::string& where) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != n) {
    return fail(ErrorCode::kParse,
                where + ": '" + key + "' must be an array of " + std::to_string(n) + " numbers");
  }
  std::vector<double> out;
  for (const auto& v : j[key]) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      return fail(ErrorCode::kParse, where + ": '" + key + "' holds a non-finite or non-number");
    }
    out.push_back(v.get<double>());
  }
  return out;
}

Result<Mat3> matrix(const json& j, const char* key, const std::string& where) {
  auto v = numbers(j, key, 9, where);
  if (!v) return tl::unexpected(v.error());
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = (*v)[static_cast<size_t>(i)];
  return m;
}

Result<Vec3> vector3(const json& j, const char* key, const std::string& where) {
  auto v = numbers(j, key, 3, where);
  if (!v) return tl::unexpected(v.error());
  return Vec3((*v)[0], (*v)[1], (*v)[2]);
}

json vecJson(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

Result<Mat3> rotation(const json& j, const char* key, const std::string& where) {
  auto R = matrix(j, key, where);
  if (!R) return R;
  if ((R->transpose() * *R - Mat3::Identity()).norm() > 1e-6 || R->determinant() < 0) {
    return fail(ErrorCode::kParse, where + ": '" + key + "' is not a rotation matrix");
  }
  return R;
}

Result<void> size(const json& j, int& w, int& h, const std::string& where) {
  if (!j.contains("width") || !j.contains("height") || !j["width"].is_number_integer() ||
      !j["height"].is_number_integer() || j["width"].get<int64_t>() < 2 ||
      j["height"].get<int64_t>() < 2 || j["width"].get<int64_t>() > 65536 ||
      j["height"].get<int64_t>() > 65536) {
    return fail(ErrorCode::kParse,
                where + ": 'width' and 'height' must be integers from 2 to 65536");
  }
  w = j["width"].get<int>();
  h = j["height"].get<int>();
  return {};
}

Result<geom::Intrinsics> intrinsics(const json& j, const std::string& where) {
  auto K = matrix(j, "K", where);
  if (!K) return tl::unexpected(K.error());
  if (std::abs((*K)(2, 2)) < 1e-12 || (*K)(0, 0) / (*K)(2, 2) <= 0 ||
      (*K)(1, 1) / (*K)(2, 2) <= 0) {
    return fail(ErrorCode::kParse, where + ": 'K' has no positive focal lengths");
  }
  return geom::Intrinsics::fromMatrix(*K);
}

Result<geom::Distortion> distortion(const json& j, const std::string& where) {
  geom::Distortion d;
  if (!j.contains("dist")) return d;
  auto v = numbers(j, "dist", 5, where);
  if (!v) return tl::unexpected(v.error());
  d = {(*v)[0], (*v)[1], (*v)[2], (*v)[3], (*v)[4]};
  return d;
}

std::string stringField(const json& j, const char* key, const std::string& fallback) {
  return j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : fallback;
}

double numberField(const json& j, const char* key, double fallback) {
  return j.contains(key) && j[key].is_number() && std::isfinite(j[key].get<double>())
             ? j[key].get<double>()
             : fallback;
}

Provenance provenance(const json& j) {
  Provenance p;
  if (j.contains("calibrated") && j["calibrated"].is_object()) {
    p.method = stringField(j["calibrated"], "method", "");
    p.time = stringField(j["calibrated"], "time", "");
  }
  return p;
}

json provenanceJson(const Provenance& p) {
  return {{"method", p.method}, {"time", p.time}};
}

}  // namespace

json matrixJson(const Mat3& m) {
  json a = json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.push_back(m(r, c));
  return a;
}

Result<RigCamera> cameraFromJson(const json& c, const std::string& where, size_t index) {
  if (!c.is_object()) return fail(ErrorCode::kParse, where + ": not an object");
  RigCamera out;
  out.name = stringField(c, "name", "camera" + std::to_string(index));
  if (auto ok = size(c, out.model.width, out.model.height, where); !ok)
    return tl::unexpected(ok.error());
  auto K = intrinsics(c, where);
  if (!K) return tl::unexpected(K.error());
  auto d = distortion(c, where);
  if (!d) return tl::unexpected(d.error());
  auto R = rotation(c, "R", where);
  if (!R) return tl::unexpected(R.error());
  auto t = vector3(c, "t", where);
  if (!t) return tl::unexpected(t.error());
  out.model.K = *K;
  out.model.dist = *d;
  out.model.pose = {*R, *t};
  out.rms_px = numberField(c, "reprojection_rms_px", -1);
  out.calibrated = provenance(c);
  // Absent in files written before cameras could be calibrated alone: posed.
  if (auto it = c.find("pose_known"); it != c.end()) {
    if (!it->is_boolean()) return fail(ErrorCode::kParse, where + ": 'pose_known' must be a bool");
    out.pose_known = it->get<bool>();
  }
  if (auto it = c.find("attached_to"); it != c.end() && !it->is_null()) {
    if (!it->is_string() || it->get<std::string>().empty() || it->get<std::string>().size() > 256) {
      return fail(ErrorCode::kParse, where + ": 'attached_to' must name a projector");
    }
    out.attached_to = it->get<std::string>();
  }
  return out;
}

namespace {

Result<TiltMountModel> tiltFrom(const json& j, const std::string& where) {
  if (!j.is_object()) return fail(ErrorCode::kParse, where + ": 'tilt' must be an object");
  TiltMountModel m;
  m.sensor = stringField(j, "sensor", "");
  auto mount = rotation(j, "mount", where + " tilt");
  if (!mount) return tl::unexpected(mount.error());
  m.sensor_from_projector = *mount;
  if (j.contains("offset_g")) {
    auto o = vector3(j, "offset_g", where + " tilt");
    if (!o) return tl::unexpected(o.error());
    m.calibration.offset = *o;
  }
  if (j.contains("scale")) {
    auto s = vector3(j, "scale", where + " tilt");
    if (!s) return tl::unexpected(s.error());
    if ((s->array() <= 0.1).any() || (s->array() >= 10).any()) {
      return fail(ErrorCode::kParse, where + " tilt: 'scale' must lie in (0.1, 10)");
    }
    m.calibration.scale = *s;
  }
  m.calibration_source = stringField(j, "source", "");
  m.fit_rms_g = numberField(j, "fit_rms_g", -1);
  return m;
}

// "plane_homography": {"H": 9 numbers (rows), "origin", "u", "v": 3 each}.
Result<geom::PlaneHomography> planeHomographyFrom(const json& j, const std::string& where) {
  const std::string at = where + " plane_homography";
  if (!j.is_object()) return fail(ErrorCode::kParse, at + ": must be an object");
  auto H = matrix(j, "H", at);
  if (!H) return tl::unexpected(H.error());
  auto origin = vector3(j, "origin", at);
  if (!origin) return tl::unexpected(origin.error());
  auto u = vector3(j, "u", at);
  if (!u) return tl::unexpected(u.error());
  auto v = vector3(j, "v", at);
  if (!v) return tl::unexpected(v.error());
  if (std::abs(u->norm() - 1) > 1e-6 || std::abs(v->norm() - 1) > 1e-6 ||
      std::abs(u->dot(*v)) > 1e-6) {
    return fail(ErrorCode::kParse, at + ": 'u' and 'v' must be orthonormal");
  }
  const Eigen::JacobiSVD<Mat3> svd(*H);
  if (!(svd.singularValues()(2) > 1e-12 * svd.singularValues()(0))) {
    return fail(ErrorCode::kParse, at + ": 'H' is singular");
  }
  return geom::PlaneHomography{{*origin, *u, *v}, *H};
}

Result<RigProjector> projectorFrom(const json& p, const std::string& where, size_t index) {
  if (!p.is_object()) return fail(ErrorCode::kParse, where + ": not an object");
  RigProjector out;
  out.name = stringField(p, "name", "projector" + std::to_string(index));
  out.output = stringField(p, "output", "");
  if (auto ok = size(p, out.width, out.height, where); !ok) return tl::unexpected(ok.error());
  if (p.contains("plane_homography")) {
    auto ph = planeHomographyFrom(p["plane_homography"], where);
    if (!ph) return tl::unexpected(ph.error());
    out.plane_homography = *ph;
  }
  // Without K a projector needs its plane mapping (route (b′)); otherwise K is required.
  out.intrinsics_known = p.contains("K") || !out.plane_homography;
  if (out.intrinsics_known) {
    auto K = intrinsics(p, where);
    if (!K) return tl::unexpected(K.error());
    out.K = *K;
    auto d = distortion(p, where);
    if (!d) return tl::unexpected(d.error());
    out.dist = *d;
  }
  out.pose_known = out.intrinsics_known && (p.contains("R") || p.contains("t"));
  if (out.intrinsics_known && p.contains("pose_known") && p["pose_known"].is_boolean()) {
    out.pose_known = p["pose_known"].get<bool>();
  }
  if (out.pose_known) {
    auto R = rotation(p, "R", where);
    if (!R) return tl::unexpected(R.error());
    auto t = vector3(p, "t", where);
    if (!t) return tl::unexpected(t.error());
    out.pose = {*R, *t};
  }
  out.scale_known =
      !(p.contains("translation_up_to_scale") && p["translation_up_to_scale"].is_boolean() &&
        p["translation_up_to_scale"].get<bool>());
  out.rms_px = numberField(p, "reprojection_rms_px", -1);
  out.points = static_cast<long>(numberField(p, "points", 0));
  out.calibrated = provenance(p);
  if (p.contains("tilt")) {
    auto t = tiltFrom(p["tilt"], where);
    if (!t) return tl::unexpected(t.error());
    out.tilt = *t;
  }
  if (p.contains("photometric")) out.photometric = p["photometric"];
  return out;
}

Result<void> surfaceFrom(const json& s, RigModel& rig, const std::string& where) {
  if (!s.is_object()) return fail(ErrorCode::kParse, where + ": 'surface' must be an object");
  if (s.contains("plane")) {
    auto v = numbers(s, "plane", 4, where + " surface");
    if (!v) return tl::unexpected(v.error());
    rig.surface.plane = geom::planeFromCoefficients((*v)[0], (*v)[1], (*v)[2], (*v)[3]);
    if (!rig.surface.plane) return fail(ErrorCode::kParse, where + ": surface plane has no normal");
    rig.surface.plane_rms_m = numberField(s, "rms_m", -1);
  }
  if (s.contains("mesh")) {  // version 1: the mesh of the one projector
    if (!s["mesh"].is_string())
      return fail(ErrorCode::kParse, where + ": surface 'mesh' not a string");
    if (rig.projectors.size() == 1) rig.surface.meshes[rig.projectors[0].name] = s["mesh"];
  }
  if (s.contains("meshes")) {
    if (!s["meshes"].is_object()) {
      return fail(ErrorCode::kParse, where + ": surface 'meshes' must map projectors to files");
    }
    for (const auto& [k, v] : s["meshes"].items()) {
      if (!v.is_string()) return fail(ErrorCode::kParse, where + ": surface mesh of '" + k + "'");
      rig.surface.meshes[k] = v.get<std::string>();
    }
  }
  rig.surface.unified_mesh = stringField(s, "unified_mesh", "");
  if (s.contains("object")) {
    const json& o = s["object"];
    const std::string at = where + " surface object";
    if (!o.is_object() || !o.contains("mesh") || !o["mesh"].is_string())
      return fail(ErrorCode::kParse, at + ": needs 'mesh', a file name");
    RigObject object;
    object.mesh = o["mesh"].get<std::string>();
    if (o.contains("R")) {
      auto R = rotation(o, "R", at);
      if (!R) return tl::unexpected(R.error());
      object.R = *R;
    }
    if (o.contains("t")) {
      auto t = vector3(o, "t", at);
      if (!t) return tl::unexpected(t.error());
      object.t = *t;
    }
    object.fit_rms_m = numberField(o, "fit_rms_m", -1);
    object.points = static_cast<long>(std::clamp(numberField(o, "points", 0), 0.0, 1e9));
    object.placed = provenance(json{{"calibrated", o.value("placed", json::object())}});
    rig.surface.object = std::move(object);
  }
  return {};
}

Result<void> viewerFrom(const json& v, RigModel& rig, const std::string& where) {
  if (!v.is_object()) return fail(ErrorCode::kParse, where + ": 'viewer' must be an object");
  if (v.contains("position")) {
    auto p = vector3(v, "position", where + " viewer");
    if (!p) return tl::unexpected(p.error());
    rig.viewer.position = *p;
  }
  rig.viewer.tracker = stringField(v, "tracker", "");
  return {};
}

}  // namespace

geom::CameraModel RigProjector::model() const {
  geom::CameraModel m;
  m.K = K;
  m.dist = dist;
  m.pose = pose;
  m.width = width;
  m.height = height;
  return m;
}

const RigCamera* RigModel::camera(const std::string& name) const {
  for (const auto& c : cameras)
    if (c.name == name) return &c;
  return nullptr;
}

const RigCamera* RigModel::attachedCamera(const std::string& name) const {
  for (const auto& c : cameras)
    if (c.attached_to == name && c.pose_known) return &c;
  return nullptr;
}

const RigProjector* RigModel::projector(const std::string& name) const {
  for (const auto& p : projectors)
    if (p.name == name) return &p;
  return nullptr;
}

const RigProjector* RigModel::projectorForOutput(const std::string& output) const {
  for (const auto& p : projectors)
    if (p.output == output) return &p;
  for (const auto& p : projectors)
    if (p.output.empty() && p.name == output) return &p;
  // A version 1 rig binds its one projector to whichever output there is.
  if (projectors.size() == 1 && projectors[0].output.empty()) return &projectors[0];
  return nullptr;
}

Result<RigModel> rigFromJson(const json& doc, const std::string& where) {
  if (!doc.is_object()) return fail(ErrorCode::kParse, where + ": not a JSON object");
  int version = 1;
  if (doc.contains("version")) {
    if (!doc["version"].is_number_integer()) {
      return fail(ErrorCode::kParse, where + ": 'version' must be an integer");
    }
    version = doc["version"].get<int>();
  }
  if (version < 1 || version > kRigVersion) {
    return fail(ErrorCode::kInvalidInput, where + ": rig.json version " + std::to_string(version) +
                                              " is not supported (this procamd reads 1 to " +
                                              std::to_string(kRigVersion) + ")");
  }
  RigModel rig;
  for (const char* key : {"cameras", "projectors"}) {
    if (doc.contains(key) && (!doc[key].is_array() || doc[key].size() > kMaxDevices)) {
      return fail(ErrorCode::kParse, where + ": '" + key + "' must be an array of at most " +
                                         std::to_string(kMaxDevices));
    }
  }
  if (doc.contains("cameras")) {
    for (const auto& c : doc["cameras"]) {
      auto cam = cameraFromJson(c, where + " camera " + std::to_string(rig.cameras.size()),
                                rig.cameras.size());
      if (!cam) return tl::unexpected(cam.error());
      if (rig.camera(cam->name))
        return fail(ErrorCode::kParse, where + ": camera '" + cam->name + "' twice");
      rig.cameras.push_back(std::move(*cam));
    }
  }
  if (doc.contains("projectors")) {
    for (const auto& p : doc["projectors"]) {
      auto proj = projectorFrom(p, where + " projector " + std::to_string(rig.projectors.size()),
                                rig.projectors.size());
      if (!proj) return tl::unexpected(proj.error());
      if (rig.projector(proj->name)) {
        return fail(ErrorCode::kParse, where + ": projector '" + proj->name + "' twice");
      }
      rig.projectors.push_back(std::move(*proj));
    }
  }
  if (doc.contains("surface") && !doc["surface"].is_null()) {
    if (auto ok = surfaceFrom(doc["surface"], rig, where); !ok) return tl::unexpected(ok.error());
  }
  if (doc.contains("viewer") && !doc["viewer"].is_null()) {
    if (auto ok = viewerFrom(doc["viewer"], rig, where); !ok) return tl::unexpected(ok.error());
  }
  return rig;
}

Result<RigModel> rigFromText(std::string_view text, const std::string& where) {
  auto doc = json::parse(text, nullptr, false);
  if (doc.is_discarded()) return fail(ErrorCode::kParse, where + ": not valid JSON");
  return rigFromJson(doc, where);
}

json rigToJson(const RigModel& rig) {
  json j;
  j["version"] = kRigVersion;
  j["cameras"] = json::array();
  for (const auto& c : rig.cameras) {
    const auto& m = c.model;
    json cj = {{"name", c.name},
               {"width", m.width},
               {"height", m.height},
               {"K", matrixJson(m.K.matrix())},
               {"dist", {m.dist.k1, m.dist.k2, m.dist.p1, m.dist.p2, m.dist.k3}},
               {"R", matrixJson(m.pose.R)},
               {"t", vecJson(m.pose.t)},
               {"pose_known", c.pose_known},
               {"calibrated", provenanceJson(c.calibrated)}};
    if (c.rms_px >= 0) cj["reprojection_rms_px"] = c.rms_px;
    if (!c.attached_to.empty()) cj["attached_to"] = c.attached_to;
    j["cameras"].push_back(std::move(cj));
  }
  j["projectors"] = json::array();
  for (const auto& p : rig.projectors) {
    json pj = {{"name", p.name},     {"width", p.width},
               {"height", p.height}, {"pose_known", p.pose_known && p.intrinsics_known},
               {"points", p.points}, {"calibrated", provenanceJson(p.calibrated)}};
    if (p.intrinsics_known || !p.plane_homography) {
      pj["K"] = matrixJson(p.K.matrix());
      pj["dist"] = {p.dist.k1, p.dist.k2, p.dist.p1, p.dist.p2, p.dist.k3};
    }
    if (p.plane_homography) {
      const geom::PlaneHomography& ph = *p.plane_homography;
      pj["plane_homography"] = {{"H", matrixJson(ph.H)},
                                {"origin", vecJson(ph.basis.origin)},
                                {"u", vecJson(ph.basis.u)},
                                {"v", vecJson(ph.basis.v)}};
    }
    if (p.pose_known && p.intrinsics_known) {
      pj["R"] = matrixJson(p.pose.R);
      pj["t"] = vecJson(p.pose.t);
    }
    if (!p.output.empty()) pj["output"] = p.output;
    if (p.rms_px >= 0) pj["reprojection_rms_px"] = p.rms_px;
    if (!p.scale_known) pj["translation_up_to_scale"] = true;
    if (p.tilt) {
      const auto& t = *p.tilt;
      pj["tilt"] = {{"sensor", t.sensor},
                    {"mount", matrixJson(t.sensor_from_projector)},
                    {"offset_g", vecJson(t.calibration.offset)},
                    {"scale", vecJson(t.calibration.scale)},
                    {"source", t.calibration_source}};
      if (t.fit_rms_g >= 0) pj["tilt"]["fit_rms_g"] = t.fit_rms_g;
    }
    if (!p.photometric.is_null()) pj["photometric"] = p.photometric;
    j["projectors"].push_back(std::move(pj));
  }
  if (!rig.surface.empty()) {
    json s = json::object();
    if (rig.surface.plane) {
      const auto& pl = *rig.surface.plane;
      s["plane"] = {pl.n.x(), pl.n.y(), pl.n.z(), pl.d};
      if (rig.surface.plane_rms_m >= 0) s["rms_m"] = rig.surface.plane_rms_m;
    }
    if (!rig.surface.meshes.empty()) s["meshes"] = rig.surface.meshes;
    if (!rig.surface.unified_mesh.empty()) s["unified_mesh"] = rig.surface.unified_mesh;
    if (const auto& o = rig.surface.object) {
      json oj = {{"mesh", o->mesh},
                 {"R", matrixJson(o->R)},
                 {"t", vecJson(o->t)},
                 {"points", o->points},
                 {"placed", provenanceJson(o->placed)}};
      if (o->fit_rms_m >= 0) oj["fit_rms_m"] = o->fit_rms_m;
      s["object"] = std::move(oj);
    }
    j["surface"] = std::move(s);
  }
  if (!rig.viewer.empty()) {
    json v = json::object();
    if (rig.viewer.position) v["position"] = vecJson(*rig.viewer.position);
    if (!rig.viewer.tracker.empty()) v["tracker"] = rig.viewer.tracker;
    j["viewer"] = std::move(v);
  }
  return j;
}

RigModel mergeRig(RigModel base, const RigModel& update) {
  for (const auto& c : update.cameras) {
    auto it = std::find_if(base.cameras.begin(), base.cameras.end(),
                           [&](const RigCamera& b) { return b.name == c.name; });
    if (it != base.cameras.end()) {
      // A recalibrated camera stays on the projector it is mounted on.
      const std::string attached = it->attached_to;
      *it = c;
      if (it->attached_to.empty()) it->attached_to = attached;
    } else {
      base.cameras.push_back(c);
    }
  }
  for (const auto& p : update.projectors) {
    auto it = std::find_if(base.projectors.begin(), base.projectors.end(),
                           [&](const RigProjector& b) { return b.name == p.name; });
    if (it != base.projectors.end()) {
      RigProjector merged = p;
      // A calibration that does not involve the tilt sensor keeps its mount.
      if (!merged.tilt) merged.tilt = it->tilt;
      if (merged.photometric.is_null()) merged.photometric = it->photometric;
      *it = std::move(merged);
    } else {
      base.projectors.push_back(p);
    }
  }
  if (update.surface.plane) {
    base.surface.plane = update.surface.plane;
    base.surface.plane_rms_m = update.surface.plane_rms_m;
  }
  for (const auto& [proj, file] : update.surface.meshes) base.surface.meshes[proj] = file;
  if (!update.surface.unified_mesh.empty()) base.surface.unified_mesh = update.surface.unified_mesh;
  if (update.surface.object) base.surface.object = update.surface.object;
  if (update.viewer.position) base.viewer.position = update.viewer.position;
  if (!update.viewer.tracker.empty()) base.viewer.tracker = update.viewer.tracker;
  return base;
}

}  // namespace procam::rig
