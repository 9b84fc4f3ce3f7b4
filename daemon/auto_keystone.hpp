#pragma once
// Automatic keystone: tilt samples (gated by their driver, drivers/tilt/plugin) ->
// low-pass, stillness and hysteresis (keystone::TiltFilter) -> a new gravity direction -> the
// keystone solve ([Raskar02] §3.2.5, run on a worker) -> the pre-warp homography. Tilt only:
// gravity fixes pitch and roll; yaw needs the camera ([Raskar02] §6.2.2) and is 0 here.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config.hpp"
#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "keystone/accel_calibration.hpp"
#include "keystone/orientation.hpp"
#include "keystone/six_position.hpp"
#include "keystone/tilt_filter.hpp"
#include "procamd/procam_plugin.h"

namespace procam::daemon {

// What the solve needs to know about the projector.
struct ProjectorModel {
  geom::Intrinsics K;
  int width = 0, height = 0;
  std::string source;  // where K came from, for status and messages
};

// How the tilt sensor sits on the projector and how to correct its readings.
struct TiltMount {
  Mat3 sensor_from_projector = Mat3::Identity();  // row i = sensor axis i, projector frame
  keystone::AccelCalibration calibration;         // applied to readings in g
  std::string calibration_source;
};

// The mount and calibration of [keystone] in procamd.toml; kInvalidInput when
// the mount is not a rotation.
Result<TiltMount> mountFromConfig(const KeystoneConfig& config);

// The sensor side of the loop; runs on the event loop (cheap per sample).
class TiltTracker {
 public:
  static Result<TiltTracker> create(const KeystoneConfig& config, TiltMount mount);

  // One sample from the driver (m/s^2, ns). The direction of gravity in the
  // projector frame when the published estimate changed (past the hysteresis,
  // or a refinement of a still hold), else nullopt.
  std::optional<Vec3> add(const procam_tilt_sample& sample);
  void reset();
  void setCalibration(const keystone::AccelCalibration& calibration, std::string source);

  // The mean raw reading (sensor frame, g, before calibration) of the current
  // still hold and how many samples it averages; nullopt while moving.
  std::optional<std::pair<Vec3, long>> stillMean() const;

  bool still() const { return still_; }
  const TiltMount& mount() const { return mount_; }

 private:
  TiltTracker(keystone::TiltFilter filter, TiltMount mount)
      : filter_(std::move(filter)), mount_(std::move(mount)) {}

  keystone::TiltFilter filter_;
  TiltMount mount_;
  std::optional<uint64_t> last_ns_;
  bool still_ = false;
  Vec3 raw_sum_ = Vec3::Zero();  // raw readings (g) of the current still hold
  long raw_count_ = 0;
};

using keystone::SixPositionCollector;

// One keystone solution for the content size in use.
struct KeystoneEstimate {
  Mat3 H = Mat3::Identity();  // content pixels -> framebuffer pixels, H(2,2) = 1
  Vec3 down = Vec3::UnitY();  // gravity, projector frame
  keystone::Angles angles;    // pitch and roll from gravity; yaw 0
  double scale = 0;           // linear size relative to the uncorrected image
  int content_width = 0, content_height = 0;
  double sample_time = 0;  // s, the tilt sample's timestamp
};

// Pure: the pre-warp for gravity `down` (projector frame). Runs on a worker.
Result<KeystoneEstimate> solveFromDown(const ProjectorModel& projector, const Vec3& down,
                                       int content_width, int content_height);

}  // namespace procam::daemon
