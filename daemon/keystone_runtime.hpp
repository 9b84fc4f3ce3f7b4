#pragma once
// The daemon's state for automatic keystone and for what the outputs show
// (daemon_keystone.cpp). Touched on the loop thread only.
#include <atomic>
#include <chrono>
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
#include "blend/curved_display.hpp"
#include "blend/tiled_blend.hpp"
#include "content_mesh.hpp"
#include "driver.hpp"
#include "frame_pacing.hpp"
#include "keystone/dot_grid.hpp"
#include "keystone/gyro_orientation.hpp"
#include "keystone_latency.hpp"
#include "output_frames.hpp"
#include "render/cpu_renderer.hpp"
#include "render/post_render_warp.hpp"

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

  // The yaw from the camera mounted on the projector (daemon_camera_yaw.cpp): measured
  // once per still hold; the hold's wall normal is fused with every gravity published
  // in that hold, and its yaw kept while the projector moves until the next hold.
  struct CameraYaw {
    std::string camera;              // the camera device; empty: none
    std::string output;              // where the dot grid is shown
    geom::CameraModel in_projector;  // K, distortion; pose: camera from projector
    std::string unavailable;         // why the yaw is not measured (empty: it is)
    std::shared_ptr<const keystone::DotGrid> grid;
    bool measuring = false;
    std::shared_ptr<std::atomic<bool>> stop;  // of the measurement running
    bool tried_this_hold = false;
    std::optional<Vec3> normal;  // this hold's wall normal, projector frame
    std::optional<double> yaw;   // rad, kept after the hold ends
    uint64_t measurements = 0, failures = 0;
    nlohmann::json last;  // the last measurement, as reported
  };
  CameraYaw yaw;

  // The gyroscope in the tilt sensor's package (daemon_camera_yaw.cpp): its bias from
  // the still holds, and while the projector moves the orientation it carries from the
  // last still one.
  keystone::GyroBias gyro_bias;
  std::optional<keystone::GyroOrientation> gyro;
  std::optional<Mat3> gyro_anchor;  // the last orientation held still by both sensors
  uint64_t gyro_anchor_ns = 0;
  Vec3 gyro_anchor_rate = Vec3::Zero();
  uint64_t gyro_samples = 0;
  uint64_t gyro_last_ns = 0;
  // Readings more than 50 ms apart while the gyroscope carried a turn: what
  // turned between them is integrated from the two ends alone (a polled sensor whose
  // reader fell behind; a buffered one delivers every sample).
  uint64_t gyro_gaps = 0;

  // From a tilt reading's arrival to the frame drawn from it (keystone_latency.hpp): the
  // latest reading's arrival, that of the published solution not yet on an output.
  std::chrono::steady_clock::time_point reading_arrival{};
  std::optional<std::chrono::steady_clock::time_point> unshown_arrival;
  std::chrono::steady_clock::time_point grid_ended{};  // the camera yaw's dot grid, last
  KeystoneLatency latency;
  Vec3 gyro_rate = Vec3::Zero();  // the last reading, projector frame, rad/s

  // While the gyroscope carries a turn, each frame goes on the wall at a time chosen as
  // it is planned, with the orientation predicted to then (frame_pacing.hpp), on an
  // output that presents when asked (output operations version 4).
  SensorClock sensor_clock;
  DrawBudget draw_budget;
  uint64_t last_vblank_ns = 0, vblank_period_ns = 0;  // the keystone output's, if it has one
  uint64_t paced_frames = 0, paced_late = 0;          // late: shown after the time asked for
  uint64_t last_present_at_ns = 0;                    // the latest time asked for
  // The keystone solution a frame in flight carries (what `keystone_shown` reports).
  struct FrameSolution {
    uint64_t solve = 0;
    uint64_t planned_ns = 0;  // CLOCK_MONOTONIC
    Mat3 H = Mat3::Identity();
    int content_width = 0, content_height = 0;
    uint64_t present_at_ns = 0;            // 0: shown when drawn
    std::optional<double> predicted_time;  // s, sensor clock: what it was solved for
  };

  // The last published gravity and the solution made from it.
  std::optional<Vec3> down;
  double down_time = 0;
  std::optional<KeystoneEstimate> estimate;
  std::string estimate_yaw;  // where its yaw came from (cameraYawSource)
  double estimate_lead = 0;  // s: predicted ahead of its sample, to when it is shown
  uint64_t solves = 0;

  // Outputs.
  struct OutputState {
    std::weak_ptr<plugins::Device> device;             // the one the setup was handed to
    std::shared_ptr<const render::RenderSetup> setup;  // handed over (or on its way)
    std::shared_ptr<const void> content;               // what `version` numbers
    uint64_t version = 0;
    std::shared_ptr<render::CpuRenderer> fallback;     // outputs that do not render
    std::string path;                                  // render path of the latest plan
    std::string chosen;                                // render::choosePath's answer
    std::string path_note;                             // why they differ, if they do
    std::chrono::steady_clock::time_point stats_time;  // statistics last asked for
    // The non-planar setup of image content and what it was made for (rig_surfaces.cpp).
    std::shared_ptr<const render::RenderSetup> np_setup;
    std::shared_ptr<const void> np_surface;
    Vec3 np_eye = Vec3::Zero();
    cv::Size np_content;
    Mat34 np_projector = Mat34::Zero();
    bool np_tracked = false;
    std::optional<Mat34> np_fixed;
    std::shared_ptr<const void> np_curved;  // the display across outputs it is a share of
    std::optional<Mat34> viewer;            // world -> content pixels of the frame drawn
    // The frame the output last showed (setup and RGBA content) and when it was drawn.
    std::shared_ptr<const render::RenderSetup> shown_setup;
    std::shared_ptr<const cv::Mat> shown_image;
    std::chrono::steady_clock::time_point shown_at;
  };
  std::map<std::string, OutputState> output_state;
  std::map<std::string, std::shared_ptr<const cv::Mat>> patterns;  // "name WxH" -> RGBA
  int stats_timer = -1;                    // one-shot: statistics of frames drawn without them
  std::shared_ptr<const cv::Mat> content;  // RGBA, decoded on a worker
  std::map<std::string, Mesh3d> meshes;    // 3D content: output name -> what it draws
  // 3D content on a non-planar surface: output name -> the mesh drawn for the viewer.
  std::map<std::string, MeshImage> mesh_images;
  nlohmann::json mesh_info;  // `content` in replies while meshes are shown
  bool rendering = false;
  bool render_again = false;
  // The frame in flight's stop flag: set when a newer request made it obsolete.
  std::shared_ptr<std::atomic<bool>> frame_stop;
  std::vector<std::function<void(bool shown)>> frame_waiters;
  uint64_t frames = 0;
  uint64_t frames_stopped = 0;              // frames stopped midway: newer state replaced them
  std::map<std::string, FrameStats> shown;  // output name -> what it shows

  // Several projectors on one wall plane as one display (tiled_display.cpp): made on
  // the compute worker for a content size and set of outputs, used by every output.
  // The display, the 8-bit alpha masks (eq. 4.3 weights; `weights` is left empty) and
  // per tile the weight table through its response and brightness gain: measured
  // (rig.json photometric, every tile) or the assumed gamma and no gain.
  struct DisplayShares {
    cv::Size content;
    std::vector<std::string> outputs;  // in tile order
    int index(const std::string& output) const;
  };
  struct Tiled : blend::TiledBlend, DisplayShares {};
  std::shared_ptr<const Tiled> tiled;  // the display in use, if any
  std::string tiled_key;               // what `tiled` (or the job running) was made for
  std::string tiled_error;             // why there is none for tiled_key
  bool tiling = false;                 // a job runs

  // Several projectors on one non-planar surface as one display for the static viewer
  // (curved_display.cpp): the viewer's content plane, each output's lookup warp and
  // its weights and tables, as for the tiled display. The surface meshes it was made
  // from are held while it is in use.
  struct Curved : blend::CurvedBlend, DisplayShares {
    std::vector<std::shared_ptr<const void>> surfaces;
    // Per output, its post-rendering warp ([Raskar02] §4.1.3); null: none needed.
    std::vector<std::shared_ptr<const render::PostRenderWarp>> post_warps;
    nlohmann::json eye_source;  // where the eye came from (config, rig)
  };
  std::shared_ptr<const Curved> curved;
  std::string curved_key;
  std::string curved_error;
  bool curving = false;
};

}  // namespace procam::daemon
