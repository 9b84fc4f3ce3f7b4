#include "rig/rig_json.hpp"

namespace procam::rig {
namespace {

Result<std::vector<double>> numbers(const nlohmann::json& j, const char* key, std::size_t n,
                                    const std::string& where) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != n)
    return fail(ErrorCode::kParse,
                where + ": '" + key + "' must be an array of " + std::to_string(n) + " numbers");
  std::vector<double> out;
  for (const auto& v : j[key]) {
    if (!v.is_number())
      return fail(ErrorCode::kParse, where + ": '" + key + "' holds a non-number");
    out.push_back(v.get<double>());
  }
  return out;
}

nlohmann::json matrixJson(const Mat3& m) {
  nlohmann::json a = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.push_back(m(r, c));
  return a;
}

}  // namespace

Result<std::vector<NamedCamera>> camerasFromJson(const nlohmann::json& doc,
                                                 const std::string& where_doc) {
  if (!doc.is_object() || !doc.contains("cameras") || !doc["cameras"].is_array() ||
      doc["cameras"].empty())
    return fail(ErrorCode::kParse,
                where_doc + ": expected {\"cameras\": [ ... ]} with at least one camera");
  std::vector<NamedCamera> out;
  for (const auto& c : doc["cameras"]) {
    NamedCamera n;
    const std::string where = where_doc + " camera " + std::to_string(out.size());
    if (!c.is_object()) return fail(ErrorCode::kParse, where + ": not an object");
    n.name = c.value("name", "camera" + std::to_string(out.size()));
    if (!c.contains("width") || !c.contains("height") || !c["width"].is_number_integer() ||
        !c["height"].is_number_integer())
      return fail(ErrorCode::kParse, where + ": 'width' and 'height' are required integers");
    n.model.width = c["width"].get<int>();
    n.model.height = c["height"].get<int>();
    auto K = numbers(c, "K", 9, where);
    auto R = numbers(c, "R", 9, where);
    auto t = numbers(c, "t", 3, where);
    if (!K) return tl::unexpected(K.error());
    if (!R) return tl::unexpected(R.error());
    if (!t) return tl::unexpected(t.error());
    Mat3 Km, Rm;
    for (int i = 0; i < 9; ++i) Km(i / 3, i % 3) = (*K)[i], Rm(i / 3, i % 3) = (*R)[i];
    n.model.K = geom::Intrinsics::fromMatrix(Km);
    if (c.contains("dist")) {
      auto d = numbers(c, "dist", 5, where);
      if (!d) return tl::unexpected(d.error());
      n.model.dist = {(*d)[0], (*d)[1], (*d)[2], (*d)[3], (*d)[4]};
    }
    if ((Rm.transpose() * Rm - Mat3::Identity()).norm() > 1e-6 || Rm.determinant() < 0)
      return fail(ErrorCode::kParse, where + ": 'R' is not a rotation matrix");
    n.model.pose.R = Rm;
    n.model.pose.t = Vec3((*t)[0], (*t)[1], (*t)[2]);
    out.push_back(std::move(n));
  }
  return out;
}

nlohmann::json cameraJson(const NamedCamera& c) {
  const auto& m = c.model;
  nlohmann::json j = {{"name", c.name},
                      {"width", m.width},
                      {"height", m.height},
                      {"K", matrixJson(m.K.matrix())},
                      {"dist", {m.dist.k1, m.dist.k2, m.dist.p1, m.dist.p2, m.dist.k3}},
                      {"R", matrixJson(m.pose.R)},
                      {"t", {m.pose.t.x(), m.pose.t.y(), m.pose.t.z()}}};
  if (c.rms_px >= 0) j["reprojection_rms_px"] = c.rms_px;
  return j;
}

nlohmann::json projectorJson(const NamedProjector& p) {
  const auto& c = p.calibration;
  nlohmann::json j = {{"name", p.name},
                      {"width", p.width},
                      {"height", p.height},
                      {"K", matrixJson(c.K.matrix())},
                      {"R", matrixJson(c.pose.R)},
                      {"t", {c.pose.t.x(), c.pose.t.y(), c.pose.t.z()}},
                      {"reprojection_rms_px", c.rms_px},
                      {"points", c.points}};
  if (!c.scale_known) j["translation_up_to_scale"] = true;
  return j;
}

nlohmann::json surfaceJson(const surface::SurfaceModel& model, const std::string& mesh_file) {
  if (!model.planar) return {{"mesh", mesh_file}};
  return {{"plane", {model.plane.n.x(), model.plane.n.y(), model.plane.n.z(), model.plane.d}},
          {"rms_m", model.plane_rms}};
}

nlohmann::json rigJson(const std::vector<NamedCamera>& cameras, const NamedProjector& projector,
                       const nlohmann::json& surface) {
  nlohmann::json j;
  j["cameras"] = nlohmann::json::array();
  for (const auto& c : cameras) j["cameras"].push_back(cameraJson(c));
  j["projectors"] = nlohmann::json::array({projectorJson(projector)});
  if (!surface.is_null()) j["surface"] = surface;
  return j;
}

}  // namespace procam::rig
