#include "rig/rig_json.hpp"

#include "rig/rig_model.hpp"

namespace procam::rig {

// The rig model's parsing of one camera (rig_model.hpp), so that cameras.json and
// rig.json accept exactly the same camera entries.
Result<std::vector<NamedCamera>> camerasFromJson(const nlohmann::json& doc,
                                                 const std::string& where_doc) {
  if (!doc.is_object() || !doc.contains("cameras") || !doc["cameras"].is_array() ||
      doc["cameras"].empty())
    return fail(ErrorCode::kParse,
                where_doc + ": expected {\"cameras\": [ ... ]} with at least one camera");
  std::vector<NamedCamera> out;
  for (const auto& c : doc["cameras"]) {
    auto cam = cameraFromJson(c, where_doc + " camera " + std::to_string(out.size()), out.size());
    if (!cam) return tl::unexpected(cam.error());
    // A camera calibrated alone (procamd calibrate-camera) has no pose to offer.
    if (!cam->pose_known)
      return fail(ErrorCode::kInvalidInput,
                  where_doc + ": camera '" + cam->name +
                      "' has intrinsics but no pose (pose_known false): calibrate the pair "
                      "with procam-calibrate stereo first");
    out.push_back({cam->name, cam->model, -1});
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
