#pragma once
// The calibrate operation's work, apart from the daemon: its arguments, and the
// run on a worker thread that shows every structured-light frame on the output,
// waits for it to settle, captures it with its cameras, decodes and solves route
// (a) ([Raskar02] §4.1.1, two cameras) through calib::solveStereoRoute, the pipeline
// procam-calibrate uses on files, or route (b′) ([Raskar02] §4.2.4, one camera and
// the display plane) through calib::solvePlaneHomographyRoute.
#include <array>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "blend/response.hpp"
#include "calibration/board_plane.hpp"
#include "calibration/plane_homography_route.hpp"
#include "calibration/stereo_route.hpp"
#include "calibration/two_view_plane.hpp"
#include "config.hpp"
#include "drift_fiducial.hpp"
#include "driver.hpp"
#include "geometry/camera_model.hpp"
#include "structured_light/pattern_set.hpp"
#include "tl/expected.hpp"

namespace procam::daemon {

// Cameras one calibrate request may name.
inline constexpr std::size_t kMaxCalibrationCameras = 8;

// The calibrate request's arguments (PROTOCOL.md).
struct CalibrationArgs {
  sl::Mode mode = sl::Mode::kGrayPhase;
  // mode "apriltag": one frame of tags instead of the Gray sequence (route (b′) only).
  bool tags = false;
  // mode "adaptive": a coarse Gray pass first; on a plane the tag frame finishes. With
  // one camera a surface that is not planar is refused; with two the full scan follows.
  bool adaptive = false;
  int step = 1;  // one code per `step` projector pixels
  int phase_steps = 8;
  int grid = 8;              // projector pixels between solved nodes
  int settle_frames = 2;     // output frames to wait after showing a pattern
  bool auto_settle = false;  // settle_frames "auto": measure the latency first
  std::string output;        // empty: the first usable output
  // "projectors": these outputs one after the other into one rig model ("all": every
  // usable output); empty: `output` alone.
  std::vector<std::string> outputs;
  bool all_outputs = false;
  // Empty: the first usable ones; one name: route (b′); two: route (a), or route (b′)
  // from both with `plane`; more: route (b′) from cameras at several positions, the
  // first the calibrated reference (the plane given or the rig's).
  std::vector<std::string> cameras;
  std::optional<geom::Plane> plane;  // the display plane (world): route (b′)
  // Route (b′) with the display plane found from this board fixed flat on it
  // (calib::parseBoard form), seen by the camera in the white frame.
  std::optional<calib::BoardSpec> board;
  std::string board_text;
  // Also show a grey ramp and measure the projector's response and brightness
  // (blend/response.hpp); null: only when several projectors are calibrated.
  std::optional<bool> response;
};

// The message names the offending key; `defaults` ([calibration] of procamd.toml)
// give settle_frames when the request has none.
tl::expected<CalibrationArgs, std::string> parseCalibrationArgs(
    const nlohmann::json& request, const CalibrationConfig& defaults = {});

// A request's "board" (procam-calibrate's board form), bounded in cells and size;
// the message says what a board looks like otherwise.
tl::expected<calib::BoardSpec, std::string> boardArg(const nlohmann::json& value);

// A device the run uses; the shared reference keeps it alive if the daemon
// closes its entry meanwhile.
struct CalibrationDevice {
  std::string name;
  std::shared_ptr<plugins::Device> device;
};

struct CalibrationCamera {
  CalibrationDevice device;
  geom::CameraModel model;  // K, distortion, pose (world -> camera)
};

struct CalibrationPlan {
  sl::PatternSet set;
  // Set: the single-frame path, one frame of AprilTags over the framebuffer and one
  // capture per camera; its corners are the nodes of route (b′) ([Raskar02] §4.2.4:
  // on a plane a collineation needs only four). `set` then only sizes the frame, or is
  // the full scan of the adaptive pair (see `coarse`).
  std::shared_ptr<const FiducialFrame> tags;
  // Set with `tags`: the adaptive path, this coarse pass (sl::coarsePatternSet, 16x12
  // blocks) before the tag frame, to tell whether the surface is planar ([Raskar02]
  // §4.1.4's coarse binary-coded pass). With one camera on the plan's plane; with two
  // and no plane (adaptivePair) the two triangulate the plane from the tag frame, and a
  // surface that is not planar gets `set`, the full scan of route (a).
  std::optional<sl::PatternSet> coarse;
  int grid = 8;
  int settle_frames = 2;
  bool auto_settle = false;   // measure the latency (latency_probe.hpp) and settle by it
  CalibrationConfig latency;  // margin_frames, latency_repeats, latency_timeout_s
  double refresh_hz = 60;
  CalibrationDevice output;
  // Two: route (a); one: route (b′); several with a plane: route (b′) from cameras at
  // several positions (wallViews).
  std::vector<CalibrationCamera> cameras;
  std::optional<geom::Plane> plane;       // set: route (b′) on this display plane (world)
  bool plane_from_rig = false;            // the rig model's surface plane, not an argument
  std::optional<calib::BoardSpec> board;  // set: route (b′), the plane from this board
  std::string board_text;
  bool response = false;  // a grey ramp after the patterns: the projector's response
  // Route (a) on a planar scene, and the adaptive pair: the plane the run's projectors
  // share, the rig's surface plane at the start (taken when the nodes or tag corners lie
  // on it), else the first one triangulated. One object for all plans of a run; only the
  // run's worker touches it.
  std::shared_ptr<std::optional<geom::Plane>> scene_plane;

  // Set: the projector stands where this model (pose, intrinsics, distortion) has it and
  // the run measures only the plane its light falls on, a moved wall: triangulated by the
  // two cameras, or by the projector and the one camera ([Raskar02] §4.1.1); the outcome's
  // triangulated_plane, nothing solved for the projector.
  std::optional<geom::CameraModel> known_projector;

  bool planar() const { return plane || board; }
  // The adaptive path with two cameras and no plane (see `coarse`).
  bool adaptivePair() const { return coarse && !planar() && cameras.size() == 2; }
  // Route (b′) with cameras at several positions: the first camera is the calibrated
  // reference, the others need only their intrinsics; the run's projectors are solved
  // together (calib::solveWallViews) after the last scan.
  bool wallViews() const { return plane && !board && cameras.size() > 1; }

  int frames() const {
    if (!tags) return static_cast<int>(set.frames.size());
    return 1 + (coarse ? static_cast<int>(coarse->frames.size()) : 0);
  }
  int captures() const {
    return static_cast<int>(frames() * cameras.size()) +
           (response ? static_cast<int>(kRampLevels.size()) : 0);
  }
  // The grey levels of the response ramp.
  static constexpr std::array<int, 9> kRampLevels = {0, 32, 64, 96, 128, 160, 192, 224, 255};
};

struct CalibrationProgress {
  double fraction = 0;  // 0..1 over the whole run
  std::string stage;    // "capturing", "decoding", "solving"
  int capture = 0;      // captures done (of plan.captures())
  // Set when the run takes more captures than planned: the adaptive path went on to the
  // full scan. The new total.
  int captures = 0;
};

struct CalibrationHooks {
  std::function<bool()> cancelled;                           // polled between frames
  std::function<void(const CalibrationProgress&)> progress;  // from the worker thread
};

struct CalibrationFailure {
  const char* code;  // proto::code
  std::string message;
  std::string device = {};  // the device that failed, if one did
  int rc = 0;               // its PROCAM_E* code
};

struct CalibrationOutcome {
  calib::StereoRouteResult route;                      // route (a)
  std::optional<calib::PlaneHomographyResult> planar;  // route (b′)
  std::optional<calib::BoardPlane> board;              // route (b′) on a board's plane
  // Route (a) on a planar scene: the plane the two cameras triangulated, which the
  // projector then takes route (b′) on.
  std::optional<geom::PlaneFit> triangulated_plane;
  std::optional<blend::ProjectorResponse> response;  // from the grey ramp
  std::string response_note;                         // why a ramp gave no response
  std::string brightness_note;  // why a response has no brightness across the frame
  // Route (b′) from cameras at several positions: per camera, the projector nodes it
  // saw (none: too few); the planar result comes from solveWallViewsRun.
  std::vector<std::optional<calib::CollineationNodes>> wall_nodes;
  std::vector<int> decoded;  // camera pixels decoded, per camera
  int settle_frames = 0;     // waited after every pattern
  nlohmann::json latency;    // the measured latency (auto_settle; latencyJson), else null
  nlohmann::json coarse;     // the adaptive path's coarse pass: {frames, planar, ...}, else null
};

// A calibration that cannot go on for a reason of its own (code `failed`).
tl::unexpected<CalibrationFailure> calibrationFailed(const std::string& why);
// Shared with the latency probe (latency_probe.hpp).
CalibrationFailure deviceFailure(const char* family, const std::string& name, int rc,
                                 const char* what, const char* reason);
// The driver's frame as a single-channel image (a copy: the driver reuses its
// buffer); empty for an unknown pixel format.
cv::Mat grayImage(const procam_image& img);
// One frame of the camera as a single-channel image (5 s at most).
tl::expected<cv::Mat, CalibrationFailure> captureGray(const CalibrationDevice& camera);
// Shows `rgb` (CV_8UC3, the output's mode) 1:1 on `output`; the failure says `what` it
// was doing.
tl::expected<void, CalibrationFailure> showFrame(const CalibrationDevice& output,
                                                 const cv::Mat& rgb, const char* what);
// Waits `seconds`, waking every 20 ms to honour a cancel; false when cancelled.
bool waitCancellable(double seconds, const CalibrationHooks& hooks);
// Shows `rgb` on the plan's output (showFrame) and waits `settle_frames` of its refreshes
// for it to reach the screen; false when cancelled meanwhile.
tl::expected<bool, CalibrationFailure> showAndSettle(const CalibrationPlan& plan,
                                                     const cv::Mat& rgb, const char* what,
                                                     int settle_frames,
                                                     const CalibrationHooks& hooks);

// Shows black on the plan's output (its pattern size), so that it adds no light to
// another projector's scan; on a worker.
tl::expected<void, CalibrationFailure> blankOutput(const CalibrationPlan& plan);

// An output that takes no part in a calibration, and the frame size that blanks it.
struct IdleOutput {
  CalibrationDevice output;
  int width = 0, height = 0;  // its mode
};
// Shows black on it (on a worker, as the output frames are drawn).
tl::expected<void, CalibrationFailure> blankOutput(const IdleOutput& idle);

// Runs on a worker: blocks on the devices; never touches daemon state.
tl::expected<CalibrationOutcome, CalibrationFailure> runCalibration(const CalibrationPlan& plan,
                                                                    const CalibrationHooks& hooks);

// The frames to wait after showing a frame: the plan's, or with auto_settle measured by
// the latency probe (outcome.settle_frames and .latency set either way). The progress
// fraction the captures then start at (0, or 0.1 after the probe).
tl::expected<double, CalibrationFailure> settleFor(const CalibrationPlan& plan,
                                                   const CalibrationHooks& hooks,
                                                   CalibrationOutcome& outcome);

// The single-frame path (plan.tags, route (b′) with one camera and the plan's plane):
// the tag frame shown, one capture per camera, the first camera's corners fitted and
// solved as calib::solvePlaneFromNodes (tag_calibration_job.cpp).
tl::expected<CalibrationOutcome, CalibrationFailure> runTagCalibration(
    const CalibrationPlan& plan, const CalibrationHooks& hooks);
// The tag frame shown, captured and solved as above, after `settleFor` gave `out` its
// settle frames; progress from `start` on.
tl::expected<CalibrationOutcome, CalibrationFailure> tagFrameOutcome(const CalibrationPlan& plan,
                                                                     const CalibrationHooks& hooks,
                                                                     CalibrationOutcome out,
                                                                     double start);
// The tag frame shown and captured by every camera of the plan; the corners the first
// camera found, and with no plane (the adaptive pair) the second's too. kFailed when a
// camera found none or its captures are not its calibration's size.
using TagViews = std::vector<std::vector<drift::FiducialCorner>>;
tl::expected<TagViews, CalibrationFailure> captureTagFrame(const CalibrationPlan& plan,
                                                           const CalibrationHooks& hooks,
                                                           int settle_frames, double start);
// Route (b′) from the first camera's corners on `plane` (calib::solvePlaneFromNodes): sets
// out.planar and out.decoded.
tl::expected<void, CalibrationFailure> solveTagFrame(const CalibrationPlan& plan,
                                                     const TagViews& views,
                                                     const geom::Plane& plane,
                                                     CalibrationOutcome& out);
// The plane the two cameras of the adaptive pair triangulate from the corners both found
// (calib::planeFromTwoViews).
Result<calib::TwoViewPlane> tagFramePlane(const CalibrationPlan& plan, const TagViews& views);
// The adaptive path (plan.coarse with plan.tags): the coarse pass shown and captured by
// the plan's cameras, its blocks tested for one homography in each (sl::testPlanarity).
// Planar: the tag frame finishes, on the plan's plane as runTagCalibration, or (the
// adaptive pair) on the plane the two cameras triangulate from it. Not planar: with one
// camera kFailed naming the fit; with two, and when the pair's tag corners are not one
// plane after all, the full scan of route (a) follows as runCalibration
// (adaptive_calibration_job.cpp).
tl::expected<CalibrationOutcome, CalibrationFailure> runAdaptiveCalibration(
    const CalibrationPlan& plan, const CalibrationHooks& hooks);

// Several projectors whose images do not overlap scanned at once: every member shows
// the same pattern frames (the same pattern set and cameras; no board), the captures are
// decoded once and each member keeps the camera pixels of its own footprint
// (`footprints[m][c]`: camera c's CV_8U mask of member m's light; empty for a batch of
// one), then each is solved as alone. One outcome per member.
tl::expected<std::vector<CalibrationOutcome>, CalibrationFailure> runBatchCalibration(
    std::span<const CalibrationPlan* const> members,
    const std::vector<std::vector<cv::Mat>>& footprints, const CalibrationHooks& hooks);

// The scan batches of a run: a coarse pass lights each projector white alone (the others
// black) and takes every camera's view of it against one all-black view; projectors
// whose lit pixels meet in no camera (after a margin for blur) share a batch when their
// plans allow it (same pattern set and cameras, settle frames given, no board; the
// caller runs it only when some pair can share), so three projectors in a row
// take two batches, not three: light that does not overlap is told apart by where it
// falls.
struct ScanBatches {
  std::vector<std::vector<std::size_t>> batches;  // plan indices, scan order
  std::vector<std::vector<cv::Mat>> footprints;   // per plan, per camera
  int captures = 0;                               // of the coarse pass
};
tl::expected<ScanBatches, CalibrationFailure> planScanBatches(
    std::span<const CalibrationPlan* const> plans, const CalibrationHooks& hooks);
// Whether planScanBatches could put any two of `plans` in one batch (so its coarse pass
// is worth its captures); (plans + 1) x cameras captures when it runs.
bool mayBatch(std::span<const CalibrationPlan* const> plans);

}  // namespace procam::daemon
