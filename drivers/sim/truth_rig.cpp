#include "sim/truth_rig.hpp"

#include <sstream>
#include <variant>

#include "keystone/six_position.hpp"
#include "sim/sensors.hpp"

namespace procam::sim {
namespace {

constexpr double kHoldSeconds = 10.0;  // per pose: the mean's noise is sigma / sqrt(1000)

std::string vec(const Vec3& v) {
  std::ostringstream s;
  s.precision(17);
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

// A scene holding only the sensor's projector, fixed so that the sensor's `axis`
// points up (sign +1) or down (-1); the sensor keeps its noise, bias, range and units.
std::string posedScene(const ProjectorSpec& p, const TiltSensorSpec& t, int axis, double sign) {
  // sensor_from_world = Q with Q * Z = sign * e_axis, so world_from_projector = Q^T M.
  const Mat3 Q =
      Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), sign * Vec3::Unit(axis)).toRotationMatrix();
  const Mat3 world_from_projector = Q.transpose() * t.sensor_from_projector;
  const Vec3 position(0, 0, 1);
  std::ostringstream s;
  s.precision(17);
  s << "[scene]\nname = \"accel-calibration\"\n"
    << "[[projectors]]\nname = \"" << p.name << "\"\nresolution = [" << p.width << ", " << p.height
    << "]\nintrinsics = { fx = " << p.K.fx << ", fy = " << p.K.fy << ", cx = " << p.K.cx
    << ", cy = " << p.K.cy << " }\n"
    << "pose = { position = " << vec(position)
    << ", look_at = " << vec(position + world_from_projector.col(2))
    << ", up = " << vec(-world_from_projector.col(1)) << " }\n"
    << "[[tilt_sensors]]\nname = \"" << t.name << "\"\nattached_to = \"" << p.name << "\"\n"
    << "mount_matrix = [" << vec(t.sensor_from_projector.row(0)) << ", "
    << vec(t.sensor_from_projector.row(1)) << ", " << vec(t.sensor_from_projector.row(2))
    << "]\nnoise_density_ug = " << t.noise_density_ug << "\nbias_mg = " << vec(t.bias_mg)
    << "\nrate_hz = " << t.rate_hz << "\nfull_scale_g = " << t.full_scale_g << "\nunits = \""
    << (t.report_in_g ? "g" : "m/s2") << "\"\n";
  return s.str();
}

Result<rig::TiltMountModel> calibratedMount(const ProjectorSpec& p, const TiltSensorSpec& t) {
  rig::TiltMountModel m;
  m.sensor = t.name;
  m.sensor_from_projector = t.sensor_from_projector;
  keystone::SixPositionCollector holds;
  uint64_t seed = 1000;
  const double unit = t.report_in_g ? 1.0 : kStandardGravity;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      auto posed = Scene::parse(posedScene(p, t, axis, sign), "six-position pose", {});
      if (!posed) return tl::unexpected(posed.error());
      auto series = sampleTiltSeries(*posed, t.name, 0.0, kHoldSeconds, seed++);
      if (!series) return tl::unexpected(series.error());
      Vec3 sum = Vec3::Zero();
      for (const auto& s : *series) sum += s.value;
      auto pose = holds.add(sum / (unit * static_cast<double>(series->size())));
      if (!pose) return tl::unexpected(pose.error());
    }
  }
  auto fit = holds.solve();
  if (!fit) return tl::unexpected(fit.error());
  m.calibration = fit->calibration;
  m.calibration_source = "six-position calibration on the virtual rig";
  m.fit_rms_g = fit->rms;
  return m;
}

}  // namespace

Result<rig::RigModel> truthRig(const Scene& scene, double time) {
  const SceneState state = scene.at(time);
  const rig::Provenance truth{"procam-sim truth of scene '" + scene.name() + "'", ""};
  rig::RigModel out;
  for (const auto& c : scene.cameras()) {
    const CameraState* s = state.camera(c.name);
    if (!s) continue;
    rig::RigCamera camera;
    camera.name = c.name;
    camera.model = s->model;
    camera.rms_px = 0.0;
    camera.calibrated = truth;
    if (c.placement.kind == Placement::Kind::kAttached) camera.attached_to = c.placement.parent;
    out.cameras.push_back(std::move(camera));
  }
  bool planar = true;
  for (const auto& p : scene.projectors()) {
    const ProjectorState* s = state.projector(p.name);
    if (!s) continue;
    rig::RigProjector r;
    r.name = r.output = p.name;
    r.width = s->model.width;
    r.height = s->model.height;
    r.K = s->model.K;
    r.dist = s->model.dist;
    r.pose = s->model.pose;
    r.rms_px = 0;
    r.calibrated = truth;
    for (const auto& t : scene.tiltSensors()) {
      if (t.projector != p.name) continue;
      auto mount = calibratedMount(p, t);
      if (!mount) return tl::unexpected(mount.error());
      r.tilt = *mount;
    }
    out.projectors.push_back(std::move(r));
    // The surface the central ray lights, when it is a plane.
    const geom::CameraModel& model = s->model;
    auto ray = model.backproject(Vec2((model.width - 1) / 2.0, (model.height - 1) / 2.0));
    const World& world = state.world ? *state.world : scene.world();  // as it stands then
    const auto hit = ray ? world.intersect(*ray) : std::nullopt;
    if (!hit) continue;
    const Surface& surface = world.surfaces()[static_cast<size_t>(hit->surface)];
    if (!std::holds_alternative<geom::Plane>(surface.shape) &&
        !std::holds_alternative<geom::Rectangle>(surface.shape)) {
      planar = false;
      continue;
    }
    const Vec3 n = hit->hit.normal.normalized();
    const geom::Plane plane{n, -n.dot(hit->hit.point)};
    if (!out.surface.plane) {
      out.surface.plane = plane;
      out.surface.plane_rms_m = 0;
    } else if (std::abs(out.surface.plane->n.dot(n)) < 1 - 1e-9 ||
               std::abs(out.surface.plane->signedDistance(hit->hit.point)) > 1e-9) {
      planar = false;  // projectors light different planes: no one plane
    }
  }
  if (!planar) out.surface.plane.reset();
  out.viewer.position = scene.viewerPosition(time);
  return out;
}

}  // namespace procam::sim
