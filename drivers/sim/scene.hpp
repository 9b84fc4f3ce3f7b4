#pragma once
// The virtual rig's world: devices, surfaces, light and motion, read from a TOML
// scene file (schema: SCENE-FORMAT.md beside this file). Scene::at(t) evaluates
// every trajectory and rigid attachment and gives the true state of the rig.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "sim/surfaces.hpp"
#include "sim/trajectory.hpp"

namespace procam::sim {

// Where a device is: a fixed pose, a trajectory, or rigidly attached to a projector.
struct Placement {
  enum class Kind { kFixed, kTrajectory, kAttached };
  Kind kind = Kind::kFixed;
  geom::Pose fixed;        // kFixed: world -> device
  std::string trajectory;  // kTrajectory: trajectory name
  std::string parent;      // kAttached: projector name
  geom::Pose offset;       // kAttached: parent device -> this device
};

struct ProjectorSpec {
  std::string name;
  int width = 0, height = 0;
  geom::Intrinsics K;
  geom::Distortion dist;  // the lens: where a framebuffer pixel's light leaves
  Placement placement;
  double gamma = 2.2;          // framebuffer value v in [0,1] emits v^gamma
  double blur_sigma_px = 0.0;  // Gaussian pixel footprint, framebuffer pixels
  double brightness = 1.0;     // irradiance of a full-white pixel at 1 m, normal incidence
  // Its mock output presents a rendered frame at the next vblank of a 60 Hz display
  // and says when (a page flip); off: at once, when its drawing ends.
  bool vsync = false;
};

struct CameraSpec {
  std::string name;
  int width = 0, height = 0;
  geom::Intrinsics K;
  geom::Distortion dist;
  Placement placement;
  double exposure = 1.0;        // linear signal = exposure * radiance, 1 = full well at gain 1
  double gain = 1.0;            // analogue gain after the photodiode (amplifies shot noise)
  double read_noise_dn = 0.0;   // sigma of the read noise, output DN
  double full_well_e = 0.0;     // electrons at full scale and gain 1; 0 = no shot noise
  int bit_depth = 8;            // 8..16; CV_8U up to 8 bits, CV_16U above
  double response_gamma = 1.0;  // output = linear^(1/response_gamma)
  int channels = 1;             // 1 (luminance) or 3 (BGR, OpenCV order)
  int supersamples = 4;         // n*n stratified samples per pixel, n >= 2
  double psf_sigma_px = 0.0;    // lens blur: Gaussian point spread, camera pixels
  double latency_s = 0.0;  // display-to-capture: a frame at t sees the outputs of t - latency_s
  int maxDn() const { return (1 << bit_depth) - 1; }
  double electronsPerDn() const { return full_well_e / maxDn(); }  // at gain 1
};

// A rate gyroscope in the same package as a tilt sensor (an MPU-6050's gyro, an IIO
// `anglvel` channel): angular velocity in the sensor frame plus a constant bias, a bias
// that wanders (a random walk) and white noise.
struct GyroSpec {
  double noise_density_dps = 0.0;  // white noise, degrees/s per sqrt(Hz)
  Vec3 bias_dps = Vec3::Zero();    // constant bias per sensor axis, degrees/s
  double bias_walk_dps = 0.0;      // bias random walk, degrees/s per sqrt(s)
  double full_scale_dps = 0.0;     // clamp of each axis, degrees/s; 0 = unlimited
};

struct TiltSensorSpec {
  std::string name;
  std::string projector;                          // the projector it is mounted on
  Mat3 sensor_from_projector = Mat3::Identity();  // mount rotation; row i = sensor axis i
  double noise_density_ug = 0.0;                  // white noise, micro-g per sqrt(Hz)
  Vec3 bias_mg = Vec3::Zero();                    // constant bias per sensor axis, milli-g
  double rate_hz = 100.0;                         // output data rate
  double full_scale_g = 0.0;                      // clamp of each axis, g; 0 = unlimited
  bool report_in_g = false;                       // units of samples: g, or m/s^2 (default)
  std::optional<GyroSpec> gyro;                   // the package's gyroscope, if it has one
};

struct TrackerSpec {
  std::string name;
  std::string trajectory;      // what it tracks; empty = the viewer
  double noise_sigma_m = 0.0;  // isotropic position noise per sample
  double rate_hz = 60.0;
};

struct ViewerSpec {
  Placement placement;  // kFixed or kTrajectory
  int width = 640, height = 480;
  geom::Intrinsics K;  // for renderings of what the viewer perceives
};

// A step change of the rig at `time` (a scene's [[events]]): a projector or camera
// turned about its own centre (yaw, pitch, roll in its own frame: positive yaw turns the
// optical axis right, pitch up, roll clockwise seen from behind) and moved; a projector's
// zoom ring turned (its focal lengths scaled about the principal point); a surface moved.
// Devices attached to a turned projector turn with it.
struct SceneEvent {
  enum class Target { kProjector, kCamera, kSurface };
  double time = 0;
  Target target = Target::kProjector;
  std::string name;
  Vec3 rotate_deg = Vec3::Zero();  // yaw, pitch, roll
  Vec3 move_m = Vec3::Zero();      // world metres
  double zoom = 1;                 // projectors: fx and fy times this
};

// True state of every device at one time.
struct ProjectorState {
  ProjectorSpec spec;
  geom::CameraModel model;  // K, distortion, pose, resolution
};
struct CameraState {
  CameraSpec spec;
  geom::CameraModel model;
};
struct TiltSensorState {
  TiltSensorSpec spec;
  Mat3 sensor_from_world = Mat3::Identity();
};

struct SceneState {
  double time = 0;
  std::vector<ProjectorState> projectors;
  std::vector<CameraState> cameras;
  std::vector<TiltSensorState> tilt_sensors;
  geom::CameraModel viewer;  // viewer eye as a pinhole (pose, K, resolution)
  // The surfaces as they stand at this time (moved by events); the scene's own world
  // before any surface event.
  std::shared_ptr<const World> world;

  const ProjectorState* projector(std::string_view name) const;
  const CameraState* camera(std::string_view name) const;
  const TiltSensorState* tiltSensor(std::string_view name) const;
};

class Scene {
 public:
  // Parses TOML text; mesh files are resolved relative to base_dir (empty: meshes
  // are refused). `origin` names the text in error messages.
  static Result<Scene> parse(std::string_view toml_text, const std::string& origin,
                             const std::filesystem::path& base_dir);
  static Result<Scene> load(const std::filesystem::path& file);

  SceneState at(double time) const;

  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }
  const std::vector<ProjectorSpec>& projectors() const { return projectors_; }
  const std::vector<CameraSpec>& cameras() const { return cameras_; }
  const std::vector<TiltSensorSpec>& tiltSensors() const { return tilt_sensors_; }
  const std::vector<TrackerSpec>& trackers() const { return trackers_; }
  const std::vector<Trajectory>& trajectories() const { return trajectories_; }
  const ViewerSpec& viewer() const { return viewer_; }
  const std::vector<SceneEvent>& events() const { return events_; }  // in time order
  const World& world() const { return *worlds_.front(); }            // as the scene began
  Vec3 ambientRgb() const { return ambient_rgb_; }  // irradiance-like, added to every point

  const Trajectory* trajectory(std::string_view name) const;
  Vec3 viewerPosition(double time) const;

 private:
  friend class SceneBuilder;
  geom::Pose placementPose(const Placement& p, double time) const;
  // A projector's intrinsics with the zoom events on it up to `time` applied.
  geom::Intrinsics zoomed(geom::Intrinsics K, std::string_view name, double time) const;
  // A device's pose with the events on it up to `time` applied.
  geom::Pose withEvents(geom::Pose pose, SceneEvent::Target target, std::string_view name,
                        double time) const;

  std::string name_, description_;
  std::vector<ProjectorSpec> projectors_;
  std::vector<CameraSpec> cameras_;
  std::vector<TiltSensorSpec> tilt_sensors_;
  std::vector<TrackerSpec> trackers_;
  std::vector<Trajectory> trajectories_;
  ViewerSpec viewer_;
  // worlds_[k]: the surfaces after the first k surface events (worlds_[0] as read).
  std::vector<std::shared_ptr<const World>> worlds_{std::make_shared<const World>()};
  std::vector<SceneEvent> events_;
  Vec3 ambient_rgb_ = Vec3::Zero();
};

}  // namespace procam::sim
