#include "sim/truth_json.hpp"

#include <variant>

#include "sim/sensors.hpp"

namespace procam::sim {

namespace {

using nlohmann::json;

template <class Derived>
json matrixJson(const Eigen::MatrixBase<Derived>& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

json vecJson(const Vec3& v) {
  return json::array({v.x(), v.y(), v.z()});
}

json distortionJson(const geom::Distortion& d) {
  return {{"k1", d.k1}, {"k2", d.k2}, {"p1", d.p1}, {"p2", d.p2}, {"k3", d.k3}};
}

json modelJson(const std::string& name, const geom::CameraModel& m) {
  json j;
  j["name"] = name;
  j["resolution"] = {m.width, m.height};
  j["K"] = {{"fx", m.K.fx}, {"fy", m.K.fy}, {"cx", m.K.cx}, {"cy", m.K.cy}, {"skew", m.K.skew}};
  j["K_matrix"] = matrixJson(m.K.matrix());
  j["R"] = matrixJson(m.pose.R);
  j["t"] = vecJson(m.pose.t);
  j["center"] = vecJson(m.pose.center());
  j["P"] = matrixJson(m.projectionMatrix());
  return j;
}

json placementJson(const Placement& p) {
  switch (p.kind) {
    case Placement::Kind::kFixed:
      return "fixed";
    case Placement::Kind::kTrajectory:
      return {{"trajectory", p.trajectory}};
    case Placement::Kind::kAttached:
      return {{"attached_to", p.parent},
              {"R_from_parent", matrixJson(p.offset.R)},
              {"t_from_parent", vecJson(p.offset.t)}};
  }
  return nullptr;
}

json shapeJson(const Shape& shape) {
  struct Visitor {
    json operator()(const geom::Plane& s) const { return {{"normal", vecJson(s.n)}, {"d", s.d}}; }
    json operator()(const geom::Rectangle& s) const {
      return {{"origin", vecJson(s.origin)}, {"u", vecJson(s.u)}, {"v", vecJson(s.v)}};
    }
    json operator()(const geom::Box& s) const {
      return {
          {"center", vecJson(s.center)}, {"half", vecJson(s.half)}, {"axes", matrixJson(s.axes)}};
    }
    json operator()(const geom::Cylinder& s) const {
      return {{"base", vecJson(s.base)},
              {"axis", vecJson(s.axis)},
              {"radius", s.radius},
              {"height", s.height}};
    }
    json operator()(const geom::Sphere& s) const {
      json j = {{"center", vecJson(s.center)}, {"radius", s.radius}};
      if (s.cap_min > -s.radius) j["cap"] = {{"axis", vecJson(s.cap_axis)}, {"min", s.cap_min}};
      return j;
    }
    json operator()(const MeshShape& s) const {
      return {{"file", s.file},
              {"vertices", s.mesh->mesh().vertices.size()},
              {"triangles", s.mesh->mesh().faces.size()}};
    }
  };
  return std::visit(Visitor{}, shape);
}

}  // namespace

json truthJson(const Scene& scene, const SceneState& state) {
  json out;
  out["scene"] = scene.name();
  out["time"] = state.time;
  out["conventions"] =
      "world: right-handed, metres, +Z up; device: x right, y down, z forward; "
      "x_device = R x_world + t; pixel centres at integer coordinates";
  out["projectors"] = json::array();
  for (const auto& p : state.projectors) {
    json j = modelJson(p.spec.name, p.model);
    j["distortion"] = distortionJson(p.model.dist);
    j["placement"] = placementJson(p.spec.placement);
    j["gamma"] = p.spec.gamma;
    j["blur_sigma_px"] = p.spec.blur_sigma_px;
    j["brightness"] = p.spec.brightness;
    out["projectors"].push_back(j);
  }
  out["cameras"] = json::array();
  for (const auto& c : state.cameras) {
    json j = modelJson(c.spec.name, c.model);
    j["distortion"] = distortionJson(c.model.dist);
    j["placement"] = placementJson(c.spec.placement);
    j["bit_depth"] = c.spec.bit_depth;
    j["channels"] = c.spec.channels;
    j["exposure"] = c.spec.exposure;
    j["gain"] = c.spec.gain;
    j["read_noise_dn"] = c.spec.read_noise_dn;
    j["full_well_e"] = c.spec.full_well_e;
    j["response_gamma"] = c.spec.response_gamma;
    j["supersamples"] = c.spec.supersamples;
    out["cameras"].push_back(j);
  }
  out["tilt_sensors"] = json::array();
  for (const auto& s : state.tilt_sensors) {
    const double unit = s.spec.report_in_g ? 1.0 : kStandardGravity;
    out["tilt_sensors"].push_back(
        {{"name", s.spec.name},
         {"attached_to", s.spec.projector},
         {"R_sensor_from_projector", matrixJson(s.spec.sensor_from_projector)},
         {"R_sensor_from_world", matrixJson(s.sensor_from_world)},
         {"units", s.spec.report_in_g ? "g" : "m/s2"},
         {"specific_force", vecJson(unit * (s.sensor_from_world * Vec3::UnitZ()))},
         {"bias_mg", vecJson(s.spec.bias_mg)},
         {"noise_density_ug", s.spec.noise_density_ug},
         {"noise_sigma_g", tiltNoiseSigmaG(s.spec)},
         {"rate_hz", s.spec.rate_hz},
         {"full_scale_g", s.spec.full_scale_g}});
  }
  out["trackers"] = json::array();
  for (const auto& t : scene.trackers()) {
    const Vec3 target = t.trajectory.empty() ? scene.viewerPosition(state.time)
                                             : scene.trajectory(t.trajectory)->centerAt(state.time);
    out["trackers"].push_back({{"name", t.name},
                               {"tracks", t.trajectory.empty() ? "viewer" : t.trajectory},
                               {"position", vecJson(target)},
                               {"noise_sigma_m", t.noise_sigma_m},
                               {"rate_hz", t.rate_hz}});
  }
  out["viewer"] = modelJson("viewer", state.viewer);
  out["ambient_rgb"] = vecJson(scene.ambientRgb());
  out["surfaces"] = json::array();
  for (const auto& s : (state.world ? *state.world : scene.world()).surfaces()) {
    json j = shapeJson(s.shape);
    j["name"] = s.name;
    if (!s.offset.isZero()) j["moved_m"] = vecJson(s.offset);  // by events, from the shape
    j["type"] = s.type;
    j["albedo_rgb"] = vecJson(s.albedo_rgb);
    if (s.print) {
      j["board"] = {{"spec", s.print->board},
                    {"center", vecJson(s.print->center + s.offset)},
                    {"right", vecJson(s.print->right)},
                    {"down", vecJson(s.print->down)},
                    {"metres_per_px", s.print->metres_per_px}};
    }
    out["surfaces"].push_back(j);
  }
  return out;
}

}  // namespace procam::sim
