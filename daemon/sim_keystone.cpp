#include "sim_keystone.hpp"

#ifdef PROCAM_HAVE_SIM
#include <sstream>

#include "sim/scene_library.hpp"
#include "sim/sensors.hpp"
#endif

namespace procam::daemon {

#ifdef PROCAM_HAVE_SIM
namespace {

constexpr double kHoldSeconds = 10.0;  // per pose: the mean's noise is sigma / sqrt(1000)

std::string vec(const Vec3& v) {
  std::ostringstream s;
  s.precision(17);
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

// A scene holding only the sensor's projector, fixed so that the sensor's
// `axis` points up (sign +1) or down (-1); the sensor keeps its noise, bias,
// range and units.
std::string posedScene(const sim::ProjectorSpec& p, const sim::TiltSensorSpec& t, int axis,
                       double sign) {
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

}  // namespace
#endif

Result<SimKeystoneSetup> simKeystoneSetup(const std::string& scene_name,
                                          const std::string& projector,
                                          const std::string& tilt_sensor) {
#ifdef PROCAM_HAVE_SIM
  auto scene = sim::resolveScene(scene_name);
  if (!scene) return tl::unexpected(scene.error());
  const sim::ProjectorSpec* p = nullptr;
  for (const auto& spec : scene->projectors()) {
    if (spec.name == projector) p = &spec;
  }
  const sim::TiltSensorSpec* t = nullptr;
  for (const auto& spec : scene->tiltSensors()) {
    if (spec.name == tilt_sensor) t = &spec;
  }
  if (!p || !t) {
    return fail(ErrorCode::kNotFound, "scene '" + scene_name + "' has no projector '" + projector +
                                          "' with tilt sensor '" + tilt_sensor + "'");
  }
  if (t->projector != p->name) {
    return fail(ErrorCode::kNotFound,
                "tilt sensor '" + tilt_sensor + "' is not mounted on '" + projector + "'");
  }
  SimKeystoneSetup out;
  out.projector.K = p->K;
  out.projector.width = p->width;
  out.projector.height = p->height;
  out.projector.source = "scene '" + scene_name + "'";
  out.mount.sensor_from_projector = t->sensor_from_projector;

  SixPositionCollector holds;
  int hold = 0;
  const double unit = t->report_in_g ? 1.0 : sim::kStandardGravity;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      auto posed = sim::Scene::parse(posedScene(*p, *t, axis, sign), "six-position pose", {});
      if (!posed) return tl::unexpected(posed.error());
      const uint64_t seed = 1000 + static_cast<uint64_t>(hold++);
      auto series = sim::sampleTiltSeries(*posed, t->name, 0.0, kHoldSeconds, seed);
      if (!series) return tl::unexpected(series.error());
      Vec3 sum = Vec3::Zero();
      for (const auto& s : *series) sum += s.value;
      if (auto pose = holds.add(sum / (unit * static_cast<double>(series->size()))); !pose) {
        return tl::unexpected(pose.error());
      }
    }
  }
  auto fit = holds.solve();
  if (!fit) return tl::unexpected(fit.error());
  out.mount.calibration = fit->calibration;
  out.mount.calibration_source = "six-position calibration on the virtual rig";
  out.calibration_rms_g = fit->rms;
  return out;
#else
  (void)projector;
  (void)tilt_sensor;
  return fail(ErrorCode::kIo, "this procamd was built without the virtual rig; cannot run scene '" +
                                  scene_name + "'");
#endif
}

}  // namespace procam::daemon
