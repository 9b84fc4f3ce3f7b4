#pragma once
// procamd: ties the event loop, the control server, configuration, state,
// drivers and devices together. All methods run on the loop thread.
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "config.hpp"
#include "content/content_source.hpp"
#include "content_mesh.hpp"
#include "control_server.hpp"
#include "control_socket.hpp"
#include "device_manager.hpp"
#include "device_set.hpp"
#include "drift/wall_from_views.hpp"
#include "drift_runtime.hpp"
#include "event_loop.hpp"
#include "geometry/intersect.hpp"
#include "keystone/keystone_solver.hpp"
#include "keystone_runtime.hpp"
#include "object_content.hpp"
#include "output_draw.hpp"
#include "registry.hpp"
#include "render/projective_mesh.hpp"
#include "render/render_path.hpp"
#include "rig_store.hpp"
#include "settings.hpp"
#include "state_file.hpp"
#include "tracker_state.hpp"
#include "worker_pool.hpp"

namespace procam::daemon {

struct CalibrationHooks;    // calibration_job.hpp
struct CalibrationFailure;  // calibration_job.hpp
class RequestArgs;          // request_args.hpp
struct CalibrationProgress;

struct DaemonOptions {
  std::string config_path;  // empty: built-in defaults
  std::string runtime_dir = "/run/procamd";
  std::string state_dir = "/var/lib/procamd";
  std::string plugin_dir;  // overrides the config and the built-in default
  std::string sim_scene;   // non-empty: run on the virtual rig
  std::string rig_path;    // non-empty: install this rig.json in the state directory at start
};

inline constexpr const char* kRelease = PROCAM_RELEASE;

class Daemon {
 public:
  static Result<std::unique_ptr<Daemon>> create(DaemonOptions options);
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;
  ~Daemon();

  int run();

  // An output whose projector the rig model maps onto a display plane.
  // A projector's response as rig.json's photometric record gives it (if measured), read
  // once per rig model, and the part of a display's key it makes.
  struct RigResponse {
    std::optional<blend::ProjectorResponse> response;
    std::string key;
  };
  struct RigTile {
    std::string output;
    blend::DisplayTile tile;
    RigResponse response;
  };

 private:
  explicit Daemon(DaemonOptions options);
  Result<void> setup();
  void loadSettings();
  void loadDrivers();
  void openDevices();
  Result<void> openVirtualRig();
  Result<void> loadRigModel();
  // After calibrate changed rig_: consumers that read it pick it up.
  void onRigChanged();
  void onSignal(int signo);
  void housekeeping();
  void warn(const std::string& message);
  ServerOptions serverOptions() const;
  ContentAccess contentAccess() const;  // [content] roots and [limits], defaults filled in

  // commands.cpp
  void handle(ClientId client, const proto::Request& req);
  void onDisconnect(ClientId client);
  void broadcast(const std::string& event, nlohmann::json body);
  // To the watchers and to the client that started the operation.
  void operationEvent(ClientId owner, const std::string& event, nlohmann::json body);
  bool replyTo(ClientId client, const proto::Request& req, const std::string& cls,
               nlohmann::json body = nlohmann::json::object());
  void errorTo(ClientId client, const proto::Request& req, const char* code,
               const std::string& message);
  // The failure handler of a worker job that answers `req` for a held client: an
  // internal-error reply naming what went wrong, then the client released.
  WorkerPool::Failure answerFailure(ClientId client, const proto::Request& req);
  // True (and `req` refused with too-large) when the client already has its
  // [limits] client_jobs worth of jobs queued on the workers.
  bool refuseOverJobLimit(ClientId client, const proto::Request& req);
  void cmdVersion(ClientId, const proto::Request&);
  void cmdStatus(ClientId, const proto::Request&);
  void cmdDevices(ClientId, const proto::Request&);
  void cmdWatch(ClientId, const proto::Request&);
  void cmdCalibrate(ClientId, const proto::Request&);
  void cmdLatency(ClientId, const proto::Request&);          // commands_latency.cpp
  void cmdSnapshot(ClientId, const proto::Request&);         // commands_snapshot.cpp
  void cmdCalibrateCamera(ClientId, const proto::Request&);  // commands_calibrate_camera.cpp
  void cmdCancel(ClientId, const proto::Request&);
  void cmdKeystone(ClientId, const proto::Request&);
  void cmdPattern(ClientId, const proto::Request&);
  void cmdContent(ClientId, const proto::Request&);
  void cmdSave(ClientId, const proto::Request&);
  void cmdReload(ClientId, const proto::Request&);
  void cmdLogLevel(ClientId, const proto::Request&);
  // commands_object.cpp: the rig's object (shader lamps) and the look painted on it.
  void cmdObject(ClientId, const proto::Request&);
  void objectRefine(ClientId, const proto::Request&, RequestArgs& args);
  // Merges the object's update into rig.json (with `files` beside it), answers OBJECT with
  // `reply`, the rig.json path and the object, and releases the held client.
  void writeObject(ClientId client, const proto::Request& req, rig::RigModel update,
                   std::map<std::string, std::string> files, nlohmann::json reply);
  nlohmann::json objectJson() const;
  void loadObjectContent(ClientId client, const proto::Request& req, ObjectLook look);
  // Paints the object's look again for the rig and the usable outputs as they are now
  // (the rig changed, an output came or went); `why` goes to the log.
  void repaintObject(const std::string& why);
  void onObjectViewerSample();
  void clearObjectContent();
  std::vector<ObjectOutput> objectOutputs() const;
  void watchObjectOutputs();
  nlohmann::json statusJson() const;
  nlohmann::json keystoneJson() const;
  nlohmann::json contentJson() const;
  // Whatever content is shown (image, 3D, live, an object's look) is dropped.
  void dropContent();
  // content_live.cpp: shared-memory frames, raw frames and video.
  void cmdContentShare(ClientId, const proto::Request&);
  void cmdContentStream(ClientId, const proto::Request&);
  void startStream(ClientId client, const proto::Request& req,
                   Result<std::unique_ptr<content::ContentSource>> source,
                   const nlohmann::json& info);
  Result<void> startLiveContent(std::unique_ptr<content::ContentSource> source,
                                nlohmann::json info);
  void pollLiveContent();
  void stopLiveContent();
  void stopWatchingLiveContent();
  nlohmann::json liveContentJson() const;
  // daemon_keystone.cpp: auto keystone and what the outputs show.
  void setupAutoKeystone();
  void probeKeystoneInputs();
  void useKeystoneInputs(ProjectorModel projector, TiltMount mount);
  Result<void> setAutoKeystone(bool enable);
  void watchTiltSensor();
  void stopTiltPolling();
  void onTiltSample(const TiltReading& reading);
  // The gyroscope's reading with a tilt sample: the bias while still, the orientation
  // carried while moving (daemon_camera_yaw.cpp). True when it carried a turn: the
  // reading is to be solved.
  bool onGyroRate(const procam_rate_sample& rate, const Vec3& specific_force, bool was_still);
  void accelCalibrationStep(ClientId client, const proto::Request& req, const std::string& action);
  void requestSolve();
  // The keystone for the last gravity (k.down, its time as the sample's) in orientation
  // R, or from gravity alone when none; nullopt (logged) when it cannot be solved.
  std::optional<KeystoneEstimate> solveKeystone(const std::optional<Mat3>& R, cv::Size content);
  // keystone_frames.cpp: the automatic keystone's solution a frame being planned carries
  // (while a turn is carried, predicted to the time the frame is asked to go on the
  // wall); nullopt when none is shown. Reported once the frame is on the wall.
  std::optional<KeystoneRuntime::FrameSolution> planKeystoneFrame();
  void keystoneFrameShown(const KeystoneRuntime::FrameSolution& solution, const OutputDrawn& drawn);
  std::optional<Mat3> currentWarp(cv::Size content_size) const;
  // daemon_camera_yaw.cpp: the yaw from the camera mounted on the projector.
  void probeCameraYaw();
  // A still hold ended (the filter's or the gyroscope's word), or one may start.
  void endTiltHold(bool was_still);
  void forgetTiltHold();
  void startTiltHold();
  void measureCameraYaw();
  void stopCameraYaw();
  // The orientation of the keystone solve for `down`: with the camera's yaw when one was
  // measured; nullopt: gravity alone (yaw 0).
  std::optional<Mat3> keystoneOrientation(const Vec3& down) const;
  nlohmann::json cameraYawJson() const;
  nlohmann::json gyroJson() const;      // null without a gyroscope
  std::string cameraYawSource() const;  // where keystoneOrientation's yaw comes from
  // keystone_rig.cpp: keystone from the rig model's plane mapping.
  Result<keystone::KeystoneSolution> solveRigKeystone(cv::Size content) const;
  std::optional<Mat3> rigKeystoneWarp(cv::Size content) const;  // when on and solvable
  Result<void> setRigKeystone(bool enable);
  nlohmann::json rigKeystoneJson(cv::Size content) const;
  // tiled_display.cpp: several projectors of the rig on one wall as one display.
  // Usable outputs whose projectors the rig maps onto a display plane, in device order.
  std::vector<RigTile> rigTiles() const;
  // The projector's RigResponse: parsed when first asked for after the rig changed (its
  // brightness map has a thousand nodes: not parsed again on every output refresh).
  const RigResponse& rigResponse(const rig::RigProjector& projector) const;
  // [keystone] display_centre / display_size: the display rectangle the configuration gives.
  std::optional<blend::WorldRect> displayRect() const;
  const KeystoneRuntime::Tiled* tiledDisplay(cv::Size content);
  nlohmann::json tiledDisplayJson() const;
  cv::Size currentSourceSize() const;
  // Draws every output again on the compute worker (one frame in flight; calls made
  // meanwhile coalesce into one frame after it). `supersede`: the state changed so that
  // the frame in flight is obsolete (other content, a pattern a client waits for); it stops.
  void refreshOutputs(std::function<void(bool shown)> done = {}, bool supersede = false);
  // What render::choosePath needs about an output, from the rig model and the viewer.
  render::SceneTraits sceneTraits(const std::string& output, bool mesh_content) const;
  // daemon_outputs.cpp: one output's frame planned on the loop (nullopt: nothing to draw).
  struct OutputDrawPolicy {
    std::chrono::steady_clock::time_point now;
    bool waited_for = false;  // a client waits for this frame
    bool live = false;        // streamed content: statistics throttled
  };
  std::optional<OutputDraw> planOutput(DeviceEntry& e, const OutputDrawPolicy& policy);
  // rig_surfaces.cpp: the rig's surface meshes (read on the I/O worker), the viewer's
  // eye, and image content on a non-planar surface (kNotFound with the reason when the
  // rig or the viewer do not allow it).
  struct RigSurfaceMesh {
    geom::MeshIntersector intersector;
    render::SurfaceMesh mesh;
  };
  struct ViewerEye {
    Vec3 position = Vec3::Zero();
    nlohmann::json source;  // {"source": "tracker" (with "tracker"), "config" or "rig"}
  };
  void loadRigSurfaces();
  std::shared_ptr<const RigSurfaceMesh> rigSurfaceFor(const std::string& projector) const;
  // A tracker's (status `viewer`), else the static one.
  std::optional<ViewerEye> viewerEye() const;
  // viewerEye() as content takes it: the position (none without a viewer) and its source.
  std::pair<std::optional<Vec3>, nlohmann::json> contentEye() const;
  // [content] viewer, else the rig model's.
  std::optional<ViewerEye> staticEye() const;
  // `fixed_viewer`: content drawn for that world -> image matrix (3D content), shown by
  // the lookup warp with it whatever the viewer does since.
  // `share`: set to the output's index in the display across outputs it draws a share
  // of, -1 when it draws alone.
  Result<std::shared_ptr<const render::RenderSetup>> nonPlanarSetup(
      const std::string& output, const render::SceneTraits& traits, cv::Size mode, cv::Size content,
      const Mat34* fixed_viewer = nullptr, int* share = nullptr);
  // curved_display.cpp: usable outputs whose calibrated projectors light the rig's
  // surface meshes, as one display for the static viewer (null until made, or with
  // fewer than two such outputs).
  const KeystoneRuntime::Curved* curvedDisplay(cv::Size content, const ViewerEye& eye);
  nlohmann::json curvedDisplayJson() const;
  bool calibrating() const;
  // Marks `op_id` as the calibration operation using `devices` (commands_calibrate.cpp).
  void beginCalibrationOp(const std::string& op_id, std::vector<std::string> devices);
  // Its worker's hooks: the cancel flag, and progress events posted to the loop
  // while the operation exists.
  CalibrationHooks operationHooks(
      ClientId client, const std::string& op_id, std::shared_ptr<std::atomic<bool>> cancelled,
      std::function<nlohmann::json(const CalibrationProgress&)> progress);
  // Why a run that held devices stopped: its error, else `cancelled` (a cancel), with
  // the device that went away named when one did.
  CalibrationFailure stoppedRun(const CalibrationFailure* error, const char* cancelled) const;
  // The end of such a run (calibrate, latency, calibrate-camera): the devices are free,
  // the client gets `reply` as `reply_class` or the failure, the finished event goes
  // out, the client is released and a lost device goes to the device manager.
  void endDeviceOp(ClientId client, const proto::Request& req, const std::string& op_id,
                   const char* kind, const char* reply_class, const nlohmann::json& reply,
                   const CalibrationFailure* failure);
  // Merges `update` and its meshes into rig.json on the I/O worker (fsync may block; a
  // failure leaves rig.json as it was), then on the loop takes the merged model and
  // calls `done` with rig.json's path or the error; onRigChanged() follows a success.
  void writeRig(rig::RigModel update, std::map<std::string, std::string> meshes,
                std::function<void(const Result<std::string>&)> done);
  void loadContentAtStart();
  nlohmann::json outputsJson() const;
  Result<void> reloadConfig();
  // daemon_tracker.cpp: trackers read at their rate, registrations, camera frame counts.
  void setupTrackers();
  void syncTrackerPolls();
  void onTrackerSample(const std::string& name, const procam_pose_sample& sample);
  void cmdTracker(ClientId, const proto::Request&);
  nlohmann::json trackersJson() const;
  nlohmann::json viewerJson() const;
  // content_follow.cpp: 3D content drawn again for a tracked viewer who moved.
  void followMeshViewer(PreparedMesh& prepared);
  void onMeshViewerSample();
  void addReadingStats(const DeviceEntry& entry, nlohmann::json& json) const;
  // daemon_drift.cpp: recalibrate = "on-drift" on a fixed rig.
  void setupDriftCheck();
  void checkDrift();
  // The check of `out` by `camera` (null: its cameras in turn, a fiducial frame where one
  // is due); nullopt when it is not checked now (o.unavailable says why when it is not
  // checked at all).
  std::optional<std::pair<DriftCheckPlan, DriftKey>> planDriftCheck(DeviceEntry& out,
                                                                    const std::string* camera);
  void onDriftChecked(const DriftKey& key, tl::expected<DriftCheck, CalibrationFailure> r);
  // Whether a check may start now.
  bool driftMayRun() const;
  bool streamPlaying() const;     // a shared or streamed source that has not ended
  bool fiducialFramesOn() const;  // on-drift with a fiducial period
  bool heldFramesOn() const;      // on-drift-silent with a stream period
  void correctDrift(const std::string& output, const std::string& camera,
                    const drift::Misregistration& m);
  // A projector's own surface mesh told the pixels that light its vertices after the
  // projector moved from `before` to `after` (`rays`: its pixel rays before); nullopt
  // when it has no mesh of its own with pixels. kDegenerate for a vertex behind it.
  struct MeshRewrite {
    std::string file, text, before;  // the file's name, its new and its old PLY text
  };
  Result<std::optional<MeshRewrite>> ownMeshMoved(const rig::RigProjector& before,
                                                  const rig::RigProjector& after,
                                                  const render::PixelRays& rays) const;
  // The output left alone until a check finds it registered: `step` could not be made.
  void unresolveDrift(const std::string& output, const std::string& camera, const std::string& step,
                      const std::string& why, const drift::Misregistration& m);
  void correctCamera(const std::string& output, const std::string& camera,
                     const drift::Misregistration& m);
  // The wall as two cameras that see the output drift triangulate it, when it stands off
  // the rig's plane; nullopt when it does not or cannot be told.
  std::optional<drift::WallSeen> movedWall(const std::string& output, const std::string& camera);
  // Whether this check of `view` shows the fiducial frame instead of registering the
  // content (made here for `framebuffer` when needed).
  bool fiducialDue(DriftRuntime::Output& o, const DriftRuntime::View& view,
                   const KeystoneRuntime::OutputState& shown, cv::Size framebuffer);
  bool holdDue(DriftRuntime::Output& o);
  // A check's fiducial frame is over: the content is drawn again.
  void endFiducialFrame(const std::string& output);
  // The wall as the output's projector and its one camera triangulate it, when the
  // content's shift is a moved wall's (drift::wallFromOneCamera) standing off the rig's
  // plane; nullopt otherwise.
  std::optional<drift::WallSeen> movedWallOneCamera(const std::string& output,
                                                    const std::string& camera);
  // `seen_by`: what triangulated the wall ("two cameras", ...), for the log and event.
  // Under "on-drift" the wall is measured by the coarse Gray pass instead (scanForDrift
  // with `surface`); under "on-drift-silent" from the content `wall` gives.
  void correctSurface(const std::string& output, const std::string& camera,
                      const drift::Misregistration& m, const drift::WallSeen& wall,
                      const std::string& seen_by);
  // The update of `rig` for the wall `plane` (scatter `rms_m`): every projector keeps its
  // pose, and one known by its collineation with the old plane gets it from its pose and
  // the new plane; kNotFound naming a projector known only by that collineation.
  static Result<rig::RigModel> wallUpdate(const rig::RigModel& rig, const geom::Plane& plane,
                                          double rms_m);
  // Merges a correction into rig.json; `event` (a drift event's body) goes out with
  // `state` when written, "failed" otherwise; `after` first hears how the write went.
  void writeDriftCorrection(const std::string& output, rig::RigModel update, nlohmann::json event,
                            const char* state, std::map<std::string, std::string> meshes = {},
                            std::function<void(const Result<std::string>&)> after = {});
  // The projector and cameras as they were before corrections that did not converge
  // (o.before) written back into rig.json.
  void restoreBeforeDrift(DriftRuntime::Output& o);
  // `step` could not register the output (`why`): unresolved, and what corrections that
  // did not converge changed goes back (restoreBeforeDrift).
  void abandonDrift(const std::string& output, const std::string& camera, const std::string& step,
                    const std::string& why, const drift::Misregistration& m);
  // drift_scan.cpp: `step` failed (`why`): the next scan (nextDriftScan), or the output
  // abandoned (abandonDrift) when none is left.
  void escalateDrift(const std::string& output, const std::string& camera, const std::string& step,
                     const std::string& why, const drift::Misregistration& m);
  // The output's projector scanned as calibrate scans it (a calibrate operation without a
  // client), the result merged into rig.json as a correction. `surface`: the projector
  // stands, the wall moved: the scan measures only the wall's plane (wallUpdate).
  void scanForDrift(const std::string& output, const std::string& camera, DriftScan which,
                    const std::string& why, const drift::Misregistration& m, bool surface = false);
  // A surface scan's result `r`: the wall's plane written (wallUpdate) as a correction,
  // then `finish` told how that went.
  void scannedWall(const std::string& output, const std::string& camera, DriftScan which,
                   const drift::Misregistration& m, const CalibrationPlan& plan,
                   const CalibrationOutcome& r, DriftRuntime::Clock::time_point started_at,
                   const std::function<void(const CalibrationFailure*)>& finish);
  // The cameras that check a projector: those that see `centre`, the surface point the
  // middle of its frame lights.
  std::vector<const rig::RigCamera*> driftCameras(const Vec3& centre) const;
  nlohmann::json driftJson(const std::string& output) const;  // null when the policy is off
  nlohmann::json driftPolicyJson() const;

  struct Operation {
    std::string kind;
    ClientId client = 0;
    nlohmann::json request_id;
    std::shared_ptr<std::atomic<bool>> cancelled;
    std::shared_ptr<std::atomic<bool>> finish = {};  // calibrate-camera: solve now
  };

  DaemonOptions options_;
  Config config_;
  Settings settings_;
  std::unique_ptr<StateFile> settings_file_;
  // The newest settings a `save` asked for, shared with the I/O worker.
  struct SaveSlot {
    std::mutex mutex;
    std::string text;
    uint64_t requested = 0;  // saves asked for
    uint64_t written = 0;    // the newest of them on disk
  };
  std::shared_ptr<SaveSlot> save_slot_ = std::make_shared<SaveSlot>();
  std::map<std::string, LogThrottle> warn_throttles_;  // Daemon::warn, per message
  // Counts content requests (load, stream, share, clear): a load or stream that
  // completes after a later request is dropped (the workers may reorder clients).
  uint64_t content_requests_ = 0;
  rig::RigModel rig_;  // the state directory's rig.json: the only source of geometry
  // rig_'s surface meshes by projector name ("" for the unified mesh).
  std::map<std::string, std::shared_ptr<const RigSurfaceMesh>> rig_surfaces_;
  // The rig's mesh files are being read for a new rig model: rig_surfaces_ may still be
  // the old model's, so no display is solved from them and no drift check is made.
  bool rig_surfaces_loading_ = false;
  uint64_t rig_generation_ = 0;
  // rigResponse's, by projector name, for rig_generation_ rig_responses_generation_.
  mutable std::map<std::string, RigResponse> rig_responses_;
  mutable uint64_t rig_responses_generation_ = 0;
  std::vector<std::string> warnings_;
  plugins::DriverRegistry registry_;
  std::chrono::steady_clock::time_point started_;
  ListeningSocket socket_info_;
  std::map<ClientId, nlohmann::json> watchers_;  // client -> its watch request id
  std::map<std::string, Operation> operations_;
  uint64_t next_operation_ = 1;
  // The running calibrate operation (commands_calibrate.cpp).
  struct Calibration {
    std::string op;  // empty: none runs
    std::vector<std::string> devices;
    std::string removed;  // why a device it used went away (udev, lost)
    bool hooked = false;  // onDeviceRemoved registered
  };
  Calibration calibration_;
  struct ContentInfo {
    int width = 0, height = 0;
  };
  ContentInfo content_info_;
  struct LiveContent {
    std::unique_ptr<content::ContentSource> source;  // null once ended
    int timer = -1;                                  // read at the frame rate, or
    int fd = -1;                                     // read when readable
    nlohmann::json info;                             // what `content` reports about the source
    uint64_t frames = 0;                             // shown so far
    bool ended = false;                              // the last frame stays shown
  };
  std::optional<LiveContent> live_content_;  // set by `content share` / `stream`
  KeystoneRuntime keystone_rt_;
  DriftRuntime drift_rt_;
  TrackerRuntime trackers_;
  MeshFollow mesh_follow_;
  // Content on an object rig (commands_object.cpp).
  struct ObjectShow {
    std::optional<ObjectLook> look;                  // what `content load` asked for
    std::shared_ptr<const PreparedObject> prepared;  // what the outputs show
    uint64_t generation = 0;                         // of the look: a new one drops jobs
    uint64_t rig_generation = 0;                     // rig_generation_ of the frames shown
    std::string tracker;      // the viewer's tracker, when the look has a highlight
    Vec3 eye = Vec3::Zero();  // the highlight's eye of the frames shown or in flight
    uint64_t updates = 0;     // repaints for a moved viewer
    bool in_flight = false;   // a repaint runs on the compute worker
    bool again = false;       // the rig or the outputs changed while it ran
  };
  ObjectShow object_show_;
  // Object writes (place, clear, refine) started: a refine that finishes after another
  // began is of an object that is no more.
  uint64_t object_edits_ = 0;
  int object_writes_ = 0;  // of those, on their way to rig.json
  // Destroyed in reverse order: server and workers before the loop they use.
  std::unique_ptr<EventLoop> loop_;
  std::unique_ptr<WorkerPool> io_worker_;       // state writes (fsync)
  std::unique_ptr<WorkerPool> compute_worker_;  // image decoding, pipelines
  DeviceSet devices_;
  std::unique_ptr<DeviceManager> device_manager_;  // udev, hotplug, device fds, lost devices
  std::unique_ptr<ControlServer> server_;
};

}  // namespace procam::daemon
