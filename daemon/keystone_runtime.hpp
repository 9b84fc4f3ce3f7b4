#pragma once
// The daemon's state for automatic keystone and for what the outputs show
// (daemon_keystone.cpp). Touched on the loop thread only.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "auto_keystone.hpp"
#include "output_frames.hpp"

namespace procam::daemon {

struct KeystoneRuntime {
  // Auto keystone inputs; `unavailable` says why it cannot run (empty: it can).
  std::optional<ProjectorModel> projector;
  std::optional<TiltTracker> tracker;
  std::string tilt_device;
  std::string unavailable = "no tilt sensor and projector intrinsics yet";
  bool hooked = false;  // the device manager's hooks are registered
  double calibration_rms_g = -1;
  SixPositionCollector accel_holds;  // keystone accel-sample / accel-solve
  bool listening = false;            // samples of tilt_device feed the tracker
  int poll_timer = -1;               // DeviceManager::pollEvery id, for sensors without a poll fd

  // The last published gravity and the solution made from it.
  std::optional<Vec3> down;
  double down_time = 0;
  std::optional<KeystoneEstimate> estimate;
  bool solving = false;
  bool solve_again = false;
  uint64_t solves = 0;

  // Outputs.
  std::shared_ptr<const cv::Mat> content;  // RGBA, decoded on a worker
  std::map<std::string, Mesh3d> meshes;    // 3D content: output name -> what it draws
  nlohmann::json mesh_info;                // `content` in replies while meshes are shown
  bool rendering = false;
  bool render_again = false;
  std::vector<std::function<void(bool shown)>> frame_waiters;
  uint64_t frames = 0;
  std::map<std::string, FrameStats> shown;  // output name -> what it shows
};

}  // namespace procam::daemon
