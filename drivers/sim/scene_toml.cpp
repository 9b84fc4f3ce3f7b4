// Scene::parse: the TOML schema of SCENE-FORMAT.md -> Scene.
#include <algorithm>
#include <cmath>
#include <set>

#include "core/units.hpp"
#include "geometry/yaw_pitch_roll.hpp"
#include "sim/mesh_io.hpp"
#include "sim/orientation.hpp"
#include "sim/scene.hpp"
#include "sim/toml_fields.hpp"

namespace procam::sim {

using detail::Fields;
using detail::SceneFileError;

namespace {

struct WorldPose {
  Vec3 center;
  Mat3 world_from_device;
};

bool hasAnyYpr(const Fields& f) {
  return f.has("yaw_deg") || f.has("pitch_deg") || f.has("roll_deg");
}

// yaw_deg, pitch_deg, roll_deg (each default 0) in geometry/yaw_pitch_roll.hpp's convention.
geom::YawPitchRoll readYpr(const Fields& f) {
  geom::YawPitchRoll a;
  a.yaw = degToRad(f.numberIn("yaw_deg", 0, -360, 360));
  a.pitch = degToRad(f.numberIn("pitch_deg", 0, -360, 360));
  a.roll = degToRad(f.numberIn("roll_deg", 0, -360, 360));
  return a;
}

// position + (look_at [+ up] | yaw_deg/pitch_deg/roll_deg), world frame.
WorldPose readWorldPose(const Fields& f) {
  WorldPose out;
  out.center = f.vec3("position");
  if (f.has("look_at")) {
    if (hasAnyYpr(f)) f.errorHere("give either look_at/up or yaw_deg/pitch_deg/roll_deg, not both");
    const Vec3 target = f.vec3("look_at");
    const Vec3 up = f.unitVec3("up", Vec3::UnitZ());
    const Vec3 forward = target - out.center;
    if (forward.norm() < 1e-9) f.error("look_at", "must differ from position");
    if (forward.normalized().cross(up).norm() < 1e-6)
      f.error("up", "must not be parallel to the viewing direction");
    out.world_from_device = geom::Pose::lookAt(out.center, target, up).R.transpose();
  } else {
    f.unitVec3("up", Vec3::UnitZ());  // accepted but meaningless without look_at
    out.world_from_device = geom::worldFromDevice(readYpr(f));
  }
  return out;
}

geom::Intrinsics readIntrinsics(const Fields& f, int width, int height) {
  geom::Intrinsics K;
  if (f.has("hfov_deg")) {
    if (f.has("fx") || f.has("fy")) f.errorHere("give either hfov_deg or fx/fy, not both");
    const double hfov = degToRad(f.requiredIn("hfov_deg", 0, 179, true));
    K.fx = K.fy = 0.5 * width / std::tan(0.5 * hfov);
  } else {
    K.fx = f.requiredIn("fx", 0, 1e6, true);
    K.fy = f.requiredIn("fy", 0, 1e6, true);
  }
  K.cx = f.numberIn("cx", 0.5 * (width - 1), -1e5, 1e5);
  K.cy = f.numberIn("cy", 0.5 * (height - 1), -1e5, 1e5);
  K.skew = f.numberIn("skew", 0, -1e5, 1e5);
  f.finish();
  return K;
}

// OpenCV's radial-tangential model; all zero when the table is absent.
geom::Distortion readDistortion(const Fields& f) {
  geom::Distortion dist;
  if (!f.has("distortion")) return dist;
  const Fields d = f.table("distortion");
  dist.k1 = d.numberIn("k1", 0, -10, 10);
  dist.k2 = d.numberIn("k2", 0, -10, 10);
  dist.p1 = d.numberIn("p1", 0, -1, 1);
  dist.p2 = d.numberIn("p2", 0, -1, 1);
  dist.k3 = d.numberIn("k3", 0, -10, 10);
  d.finish();
  return dist;
}

class Reader {
 public:
  Reader(const std::filesystem::path& base_dir) : base_dir_(base_dir) {}

  std::vector<Trajectory> trajectories(const Fields& root) {
    std::vector<Trajectory> out;
    for (const Fields& f : root.tableArray("trajectories")) {
      const std::string name = uniqueName(f, trajectory_names_);
      std::vector<Keyframe> keys;
      for (const Fields& k : f.tableArray("keyframes")) {
        const WorldPose p = readWorldPose(k);
        Keyframe key;
        key.time = k.requiredIn("t", -1e9, 1e9);
        key.center = p.center;
        key.orientation = Eigen::Quaterniond(p.world_from_device);
        if (!keys.empty() && !(key.time > keys.back().time))
          k.error("t", "keyframe times must increase strictly");
        keys.push_back(key);
        k.finish();
      }
      if (keys.empty()) f.error("keyframes", "at least one keyframe is required");
      const std::string ease = f.optionalString("ease").value_or("linear");
      if (ease != "linear" && ease != "smooth") f.error("ease", "must be \"linear\" or \"smooth\"");
      auto traj = Trajectory::create(name, std::move(keys), f.boolean("loop", false),
                                     ease == "smooth" ? Easing::kSmooth : Easing::kLinear);
      if (!traj) f.errorHere(traj.error().message);
      out.push_back(std::move(*traj));
      f.finish();
    }
    return out;
  }

  // pose = {...} | trajectory = "..." | attached_to = "..." (+ offset = {...}).
  Placement placement(const Fields& f, bool may_attach) {
    const int count = int(f.has("pose")) + int(f.has("trajectory")) + int(f.has("attached_to"));
    if (count != 1)
      f.errorHere(may_attach ? "give exactly one of pose, trajectory, attached_to"
                             : "give exactly one of pose, trajectory");
    Placement p;
    if (f.has("pose")) {
      const Fields pose = f.table("pose");
      const WorldPose wp = readWorldPose(pose);
      pose.finish();
      p.fixed = poseFromCenter(wp.center, wp.world_from_device);
    } else if (f.has("trajectory")) {
      p.kind = Placement::Kind::kTrajectory;
      p.trajectory = f.string("trajectory");
      if (!trajectory_names_.contains(p.trajectory))
        f.error("trajectory", "no trajectory named '" + p.trajectory + "'");
    } else {
      if (!may_attach) f.error("attached_to", "only cameras and tilt sensors can be attached");
      p.kind = Placement::Kind::kAttached;
      p.parent = f.string("attached_to");
      if (!projector_names_.contains(p.parent))
        f.error("attached_to", "no projector named '" + p.parent + "'");
    }
    if (f.has("offset")) {
      if (p.kind != Placement::Kind::kAttached) f.error("offset", "only valid with attached_to");
      const Fields off = f.table("offset");
      const Vec3 position = off.optionalVec3("position").value_or(Vec3::Zero());
      p.offset = childFromParent(position, geom::parentFromChild(readYpr(off)));
      off.finish();
    }
    return p;
  }

  ProjectorSpec projector(const Fields& f) {
    ProjectorSpec s;
    s.name = uniqueName(f, projector_names_);
    const auto res = f.resolution("resolution");
    s.width = res[0];
    s.height = res[1];
    s.K = readIntrinsics(f.table("intrinsics"), s.width, s.height);
    s.dist = readDistortion(f);
    s.placement = placement(f, false);
    s.gamma = f.numberIn("gamma", 2.2, 0.1, 10);
    s.blur_sigma_px = f.numberIn("blur_sigma_px", 0, 0, 50);
    s.brightness = f.numberIn("brightness", 1, 0, 1e9);
    s.vsync = f.boolean("vsync", false);
    f.finish();
    return s;
  }

  CameraSpec camera(const Fields& f) {
    CameraSpec s;
    s.name = uniqueName(f, camera_names_);
    const auto res = f.resolution("resolution");
    s.width = res[0];
    s.height = res[1];
    s.K = readIntrinsics(f.table("intrinsics"), s.width, s.height);
    s.dist = readDistortion(f);
    s.placement = placement(f, true);
    s.exposure = f.numberIn("exposure", 1, 0, 1e9, true);
    s.gain = f.numberIn("gain", 1, 0, 1e6, true);
    s.bit_depth = f.integerIn("bit_depth", 8, 8, 16);
    s.read_noise_dn = f.numberIn("read_noise_dn", 0, 0, 1e5);
    if (f.has("full_well_e") && f.has("electrons_per_dn"))
      f.errorHere("give either full_well_e or electrons_per_dn, not both");
    s.full_well_e = f.numberIn("full_well_e", 0, 0, 1e9, true);
    if (f.has("electrons_per_dn"))
      s.full_well_e = f.requiredIn("electrons_per_dn", 0, 1e6, true) * s.maxDn();
    s.response_gamma = f.numberIn("response_gamma", 1, 0.1, 10);
    s.channels = f.integerIn("channels", 1, 1, 3);
    if (s.channels == 2) f.error("channels", "must be 1 or 3");
    s.psf_sigma_px = f.numberIn("psf_sigma_px", 0, 0, 20);
    s.latency_s = f.numberIn("latency_s", 0, 0, 10);
    s.supersamples = f.integerIn("supersamples", 4, 4, 256);
    const int n = static_cast<int>(std::lround(std::sqrt(s.supersamples)));
    if (n * n != s.supersamples) f.error("supersamples", "must be a square number (4, 9, 16, ...)");
    f.finish();
    return s;
  }

  Surface surface(const Fields& f) {
    Surface s;
    s.name = uniqueName(f, surface_names_);
    s.type = f.string("type");
    s.albedo_rgb = f.scalarOrVec3("albedo", Vec3::Constant(0.8), 0, 1);
    if (s.type == "plane") {
      geom::Plane p;
      p.n = f.unitVec3("normal", Vec3::UnitZ());
      p.d = -p.n.dot(f.vec3("point"));
      s.shape = p;
    } else if (s.type == "rectangle") {
      s.shape = rectangle(f);
    } else if (s.type == "box") {
      geom::Box b;
      b.center = f.vec3("center");
      b.half = 0.5 * f.vec3("size");
      if (b.half.minCoeff() <= 0) f.error("size", "all sizes must be > 0");
      b.axes = worldTurn(readYpr(f));
      s.shape = b;
    } else if (s.type == "cylinder") {
      geom::Cylinder c;
      c.base = f.vec3("base");
      c.axis = f.unitVec3("axis", Vec3::UnitZ());
      c.radius = f.requiredIn("radius", 0, 1e6, true);
      c.height = f.requiredIn("height", 0, 1e6, true);
      s.shape = c;
    } else if (s.type == "sphere" || s.type == "dome") {
      geom::Sphere sp;
      sp.center = f.vec3("center");
      sp.radius = f.requiredIn("radius", 0, 1e6, true);
      if (s.type == "dome") {
        sp.cap_axis = f.unitVec3("axis", Vec3::UnitZ());
        sp.cap_min = f.numberIn("cut", 0, -sp.radius, sp.radius);
      }
      s.shape = sp;
    } else if (s.type == "mesh") {
      s.shape = mesh(f);
    } else {
      f.error("type", "unknown surface type '" + s.type +
                          "' (plane, rectangle, box, cylinder, sphere, dome, mesh)");
    }
    if (f.has("board")) s.print = boardPrint(f, s.shape);
    f.finish();
    return s;
  }

  TiltSensorSpec tiltSensor(const Fields& f) {
    TiltSensorSpec s;
    s.name = uniqueName(f, sensor_names_);
    s.projector = f.string("attached_to");
    if (!projector_names_.contains(s.projector))
      f.error("attached_to", "no projector named '" + s.projector + "'");
    if (f.has("mount") && f.has("mount_matrix"))
      f.errorHere("give either mount or mount_matrix, not both");
    if (f.has("mount")) {
      const Fields m = f.table("mount");
      s.sensor_from_projector = geom::parentFromChild(readYpr(m)).transpose();
      m.finish();
    } else if (f.has("mount_matrix")) {
      const Mat3 m = f.matrix3("mount_matrix");
      if ((m * m.transpose() - Mat3::Identity()).norm() > 1e-6 || m.determinant() < 0)
        f.error("mount_matrix", "must be a rotation (orthonormal rows, determinant +1)");
      s.sensor_from_projector = m;
    }
    s.noise_density_ug = f.numberIn("noise_density_ug", 0, 0, 1e6);
    s.bias_mg = f.scalarOrVec3("bias_mg", Vec3::Zero(), -1e4, 1e4);
    s.rate_hz = f.numberIn("rate_hz", 100, 0, 1e6, true);
    s.full_scale_g = f.numberIn("full_scale_g", 0, 0, 1e3);
    const std::string units = f.optionalString("units").value_or("m/s2");
    if (units != "m/s2" && units != "g") f.error("units", "must be \"m/s2\" or \"g\"");
    s.report_in_g = units == "g";
    if (f.has("gyro")) {
      const Fields g = f.table("gyro");
      GyroSpec gyro;
      gyro.noise_density_dps = g.numberIn("noise_density_dps", 0, 0, 100);
      gyro.bias_dps = g.scalarOrVec3("bias_dps", Vec3::Zero(), -1e3, 1e3);
      gyro.bias_walk_dps = g.numberIn("bias_walk_dps", 0, 0, 100);
      gyro.full_scale_dps = g.numberIn("full_scale_dps", 0, 0, 1e5);
      g.finish();
      s.gyro = gyro;
    }
    f.finish();
    return s;
  }

  // [[events]]: `t`, `target` (a projector, camera or surface), `rotate_deg` (devices),
  // `move_m` and/or `zoom` (projectors).
  SceneEvent event(const Fields& f) {
    SceneEvent e;
    e.time = f.requiredIn("t", 0, 1e6);
    e.name = f.string("target");
    const int kinds = projector_names_.contains(e.name) + camera_names_.contains(e.name) +
                      surface_names_.contains(e.name);
    if (kinds > 1)
      f.error("target", "'" + e.name + "' names more than one projector, camera or surface");
    if (projector_names_.contains(e.name)) {
      e.target = SceneEvent::Target::kProjector;
    } else if (camera_names_.contains(e.name)) {
      e.target = SceneEvent::Target::kCamera;
    } else if (surface_names_.contains(e.name)) {
      e.target = SceneEvent::Target::kSurface;
    } else {
      f.error("target", "no projector, camera or surface named '" + e.name + "'");
    }
    const auto rotate = f.optionalVec3("rotate_deg");
    const auto move = f.optionalVec3("move_m");
    const bool zoom = f.has("zoom");
    if (!rotate && !move && !zoom)
      f.errorHere("an event turns, moves or zooms its target: rotate_deg, move_m or zoom");
    if (zoom && e.target != SceneEvent::Target::kProjector)
      f.error("zoom", "only a projector has a zoom ring");
    e.zoom = zoom ? f.numberIn("zoom", 1, 0.5, 2) : 1.0;
    if (rotate && rotate->cwiseAbs().maxCoeff() > 180)
      f.error("rotate_deg", "each angle must lie in [-180, 180]");
    if (move && move->cwiseAbs().maxCoeff() > 100)
      f.error("move_m", "each component must lie in [-100, 100] m");
    if (rotate && e.target == SceneEvent::Target::kSurface)
      f.error("rotate_deg", "a surface can only be moved (move_m)");
    e.rotate_deg = rotate.value_or(Vec3::Zero());
    e.move_m = move.value_or(Vec3::Zero());
    f.finish();
    return e;
  }

  TrackerSpec tracker(const Fields& f) {
    TrackerSpec s;
    s.name = uniqueName(f, tracker_names_);
    s.noise_sigma_m = f.numberIn("noise_sigma_m", 0, 0, 10);
    s.rate_hz = f.numberIn("rate_hz", 60, 0, 1e6, true);
    s.trajectory = f.optionalString("trajectory").value_or("");
    if (!s.trajectory.empty() && !trajectory_names_.contains(s.trajectory))
      f.error("trajectory", "no trajectory named '" + s.trajectory + "'");
    f.finish();
    return s;
  }

  ViewerSpec viewer(const Fields& f) {
    ViewerSpec s;
    s.placement = placement(f, false);
    const auto res =
        f.has("resolution") ? f.resolution("resolution") : std::array<int, 2>{640, 480};
    s.width = res[0];
    s.height = res[1];
    if (f.has("intrinsics")) {
      s.K = readIntrinsics(f.table("intrinsics"), s.width, s.height);
    } else {
      s.K.fx = s.K.fy = 0.5 * s.width / std::tan(degToRad(30));  // 60 degrees wide
      s.K.cx = 0.5 * (s.width - 1);
      s.K.cy = 0.5 * (s.height - 1);
    }
    f.finish();
    return s;
  }

 private:
  // A body (box, mesh) turned in the world by the angles a device at rest would turn by.
  static Mat3 worldTurn(const geom::YawPitchRoll& a) {
    return geom::worldFromDevice(a) * geom::worldFromDevice({}).transpose();
  }

  static std::string uniqueName(const Fields& f, std::set<std::string>& names) {
    std::string name = f.string("name");
    if (!names.insert(name).second) f.error("name", "duplicate name '" + name + "'");
    return name;
  }

  // board = { spec = "aprilgrid:6x4:0.15", center = [x, y, z], px_per_m = 1000 } on a
  // plane or a rectangle (SCENE-FORMAT.md).
  std::shared_ptr<const SurfacePrint> boardPrint(const Fields& f, const Shape& shape) {
    Vec3 point, normal;
    if (const auto* p = std::get_if<geom::Plane>(&shape)) {
      normal = p->n;
      point = -p->d * p->n;
    } else if (const auto* r = std::get_if<geom::Rectangle>(&shape)) {
      normal = r->u.cross(r->v).normalized();
      point = r->origin;
    } else {
      f.error("board", "a board can only be printed on a plane or a rectangle");
    }
    const Fields b = f.table("board");
    const std::string spec = b.string("spec");
    const Vec3 center = b.vec3("center");
    const double px_per_m = b.numberIn("px_per_m", 1000, 100, 20000);
    b.finish();
    auto print = makeBoardPrint(spec, center, point, normal, px_per_m);
    if (!print) f.error("board", print.error().message);
    return std::make_shared<const SurfacePrint>(std::move(*print));
  }

  geom::Rectangle rectangle(const Fields& f) {
    geom::Rectangle r;
    if (f.has("origin")) {
      if (f.has("center")) f.errorHere("give either origin/u/v or center/normal/size, not both");
      r.origin = f.vec3("origin");
      r.u = f.vec3("u");
      r.v = f.vec3("v");
      if (r.u.norm() < 1e-12 || r.v.norm() < 1e-12) f.errorHere("u and v must not be zero");
      if (std::abs(r.u.normalized().dot(r.v.normalized())) > 1e-9)
        f.errorHere("u and v must be perpendicular");
      return r;
    }
    const Vec3 center = f.vec3("center");
    const Vec3 normal = f.unitVec3("normal", Vec3::UnitZ());
    const Vec2 size = f.vec2("size");
    if (size.minCoeff() <= 0) f.error("size", "width and height must be > 0");
    const Vec3 default_up = std::abs(normal.z()) > 0.9 ? Vec3::UnitY() : Vec3::UnitZ();
    const Vec3 up_hint = f.unitVec3("up", default_up);
    const Vec3 right = up_hint.cross(normal);
    if (right.norm() < 1e-6) f.error("up", "must not be parallel to normal");
    const Vec3 up = normal.cross(right.normalized());
    r.u = right.normalized() * size.x();
    r.v = up * size.y();
    r.origin = center - 0.5 * r.u - 0.5 * r.v;
    return r;
  }

  MeshShape mesh(const Fields& f) {
    MeshShape m;
    m.file = f.string("file");
    if (base_dir_.empty())
      f.error("file", "mesh files need a scene loaded from a file (embedded scenes have none)");
    auto loaded = loadMesh(base_dir_ / m.file);
    if (!loaded) f.error("file", loaded.error().message);
    const Vec3 position = f.optionalVec3("position").value_or(Vec3::Zero());
    const double scale = f.numberIn("scale", 1, 0, 1e9, true);
    const Mat3 R = worldTurn(readYpr(f));
    for (auto& v : loaded->vertices) v = position + R * (scale * v);
    auto built = geom::MeshIntersector::build(std::move(*loaded));
    if (!built) f.error("file", built.error().message);
    m.mesh = std::make_shared<const geom::MeshIntersector>(std::move(*built));
    return m;
  }

  std::filesystem::path base_dir_;
  std::set<std::string> trajectory_names_, projector_names_, camera_names_, surface_names_,
      sensor_names_, tracker_names_;
};

}  // namespace

// Fills a Scene from the parsed document (a friend of Scene).
class SceneBuilder {
 public:
  static Scene build(const Fields& root, const std::filesystem::path& base_dir,
                     const std::string& fallback_name) {
    Scene scene;
    Reader reader(base_dir);
    scene.name_ = fallback_name;
    if (root.has("scene")) {
      const Fields s = root.table("scene");
      scene.name_ = s.optionalString("name").value_or(fallback_name);
      scene.description_ = s.optionalString("description").value_or("");
      scene.ambient_rgb_ = s.scalarOrVec3("ambient", Vec3::Zero(), 0, 1e9);
      s.finish();
    }
    scene.trajectories_ = reader.trajectories(root);
    for (const Fields& f : root.tableArray("projectors"))
      scene.projectors_.push_back(reader.projector(f));
    for (const Fields& f : root.tableArray("cameras")) scene.cameras_.push_back(reader.camera(f));
    std::vector<Surface> surfaces;
    for (const Fields& f : root.tableArray("surfaces")) surfaces.push_back(reader.surface(f));
    scene.worlds_ = {std::make_shared<const World>(std::move(surfaces))};
    for (const Fields& f : root.tableArray("tilt_sensors"))
      scene.tilt_sensors_.push_back(reader.tiltSensor(f));
    for (const Fields& f : root.tableArray("trackers"))
      scene.trackers_.push_back(reader.tracker(f));
    if (root.has("viewer")) {
      scene.viewer_ = reader.viewer(root.table("viewer"));
    } else {  // at the origin, looking along +Y, 60 degrees wide
      scene.viewer_.placement.fixed = poseFromCenter(Vec3::Zero(), geom::worldFromDevice({}));
      scene.viewer_.K.fx = scene.viewer_.K.fy = 0.5 * 640 / std::tan(degToRad(30));
      scene.viewer_.K.cx = 319.5;
      scene.viewer_.K.cy = 239.5;
    }
    for (const Fields& f : root.tableArray("events")) scene.events_.push_back(reader.event(f));
    std::stable_sort(scene.events_.begin(), scene.events_.end(),
                     [](const SceneEvent& a, const SceneEvent& b) { return a.time < b.time; });
    for (const SceneEvent& e : scene.events_) {
      if (e.target != SceneEvent::Target::kSurface) continue;
      const auto& surfaces = scene.worlds_.back()->surfaces();
      for (std::size_t i = 0; i < surfaces.size(); ++i) {
        if (surfaces[i].name != e.name) continue;
        scene.worlds_.push_back(
            std::make_shared<const World>(scene.worlds_.back()->moved(i, e.move_m)));
      }
    }
    if (scene.projectors_.empty() && scene.cameras_.empty())
      root.errorHere("a scene needs at least one projector or camera");
    root.finish();
    return scene;
  }
};

Result<Scene> Scene::parse(std::string_view toml_text, const std::string& origin,
                           const std::filesystem::path& base_dir) {
  try {
    const toml::table doc = toml::parse(toml_text, origin);
    const Fields root(doc, "", &origin);
    return SceneBuilder::build(root, base_dir, std::filesystem::path(origin).stem().string());
  } catch (const toml::parse_error& e) {
    return fail(ErrorCode::kParse, origin + ":" + std::to_string(e.source().begin.line) + ": " +
                                       std::string(e.description()));
  } catch (const SceneFileError& e) {
    return fail(ErrorCode::kParse, e.message);
  }
}

}  // namespace procam::sim
