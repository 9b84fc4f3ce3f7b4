#include "sim/scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

#include "core/units.hpp"
#include "sim/orientation.hpp"

namespace procam::sim {

namespace {
template <class T>
const T* findByName(const std::vector<T>& items, std::string_view name) {
  for (const auto& item : items) {
    if (item.spec.name == name) return &item;
  }
  return nullptr;
}
}  // namespace

const ProjectorState* SceneState::projector(std::string_view name) const {
  return findByName(projectors, name);
}
const CameraState* SceneState::camera(std::string_view name) const {
  return findByName(cameras, name);
}
const TiltSensorState* SceneState::tiltSensor(std::string_view name) const {
  return findByName(tilt_sensors, name);
}

const Trajectory* Scene::trajectory(std::string_view name) const {
  for (const auto& t : trajectories_) {
    if (t.name() == name) return &t;
  }
  return nullptr;
}

geom::Pose Scene::placementPose(const Placement& p, double time) const {
  switch (p.kind) {
    case Placement::Kind::kFixed:
      return p.fixed;
    case Placement::Kind::kTrajectory:
      return trajectory(p.trajectory)->poseAt(time);
    case Placement::Kind::kAttached:
      // The parser guarantees the parent exists and is itself not attached; a device
      // on it follows its events.
      for (const auto& proj : projectors_) {
        if (proj.name != p.parent) continue;
        return compose(p.offset, withEvents(placementPose(proj.placement, time),
                                            SceneEvent::Target::kProjector, proj.name, time));
      }
      break;
  }
  return p.fixed;
}

geom::Pose Scene::withEvents(geom::Pose pose, SceneEvent::Target target, std::string_view name,
                             double time) const {
  for (const SceneEvent& e : events_) {
    if (e.time > time) break;
    if (e.target != target || e.name != name) continue;
    // The device's axes turn by B in its own frame about its centre: R' = B^T R.
    const Vec3 r = e.rotate_deg.unaryExpr([](double a) { return degToRad(a); });
    const Mat3 B =
        (Eigen::AngleAxisd(r.x(), Vec3::UnitY()) * Eigen::AngleAxisd(r.y(), Vec3::UnitX()) *
         Eigen::AngleAxisd(r.z(), Vec3::UnitZ()))
            .toRotationMatrix();
    const Vec3 centre = pose.center() + e.move_m;
    pose.R = B.transpose() * pose.R;
    pose.t = -pose.R * centre;
  }
  return pose;
}

geom::Intrinsics Scene::zoomed(geom::Intrinsics K, std::string_view name, double time) const {
  for (const SceneEvent& e : events_) {
    if (e.time > time) break;
    if (e.target != SceneEvent::Target::kProjector || e.name != name) continue;
    K.fx *= e.zoom;
    K.fy *= e.zoom;
    K.skew *= e.zoom;
  }
  return K;
}

Vec3 Scene::viewerPosition(double time) const {
  return placementPose(viewer_.placement, time).center();
}

SceneState Scene::at(double time) const {
  SceneState state;
  state.time = time;
  for (const auto& spec : projectors_) {
    geom::CameraModel m;
    m.K = zoomed(spec.K, spec.name, time);
    m.dist = spec.dist;
    m.pose = withEvents(placementPose(spec.placement, time), SceneEvent::Target::kProjector,
                        spec.name, time);
    m.width = spec.width;
    m.height = spec.height;
    state.projectors.push_back({spec, m});
  }
  for (const auto& spec : cameras_) {
    geom::CameraModel m;
    m.K = spec.K;
    m.dist = spec.dist;
    m.pose = withEvents(placementPose(spec.placement, time), SceneEvent::Target::kCamera, spec.name,
                        time);
    m.width = spec.width;
    m.height = spec.height;
    state.cameras.push_back({spec, m});
  }
  for (const auto& spec : tilt_sensors_) {
    const ProjectorState* proj = state.projector(spec.projector);
    state.tilt_sensors.push_back({spec, spec.sensor_from_projector * proj->model.pose.R});
  }
  state.viewer.K = viewer_.K;
  state.viewer.pose = placementPose(viewer_.placement, time);
  state.viewer.width = viewer_.width;
  state.viewer.height = viewer_.height;
  std::size_t moved = 0;
  for (const SceneEvent& e : events_) {
    if (e.time > time) break;
    moved += e.target == SceneEvent::Target::kSurface;
  }
  state.world = worlds_[std::min(moved, worlds_.size() - 1)];
  return state;
}

Result<Scene> Scene::load(const std::filesystem::path& file) {
  // A directory or FIFO would throw from the stream buffer or block; a scene is text.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    return fail(ErrorCode::kIo, "scene file " + file.string() + " is not a regular file");
  }
  if (std::filesystem::file_size(file, ec) > (std::uintmax_t{16} << 20)) {
    return fail(ErrorCode::kTooLarge, "scene file " + file.string() + " is over 16 MiB");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail(ErrorCode::kIo, "cannot open scene file " + file.string());
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::filesystem::path base = file.parent_path().empty() ? "." : file.parent_path();
  return parse(text, file.string(), base);
}

}  // namespace procam::sim
