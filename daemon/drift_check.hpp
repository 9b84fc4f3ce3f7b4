#pragma once
// One drift check of a fixed rig, on a worker: what the camera should see of the frame an
// output shows (the frame drawn again on the CPU, resampled onto a framebuffer grid; the
// grid's camera pixels from the rig model) against a few averaged camera frames
// (drift/misregistration.hpp); or, for content too plain to register, a fiducial frame
// shown on the output and its tag corners found (drift/fiducial_misregistration.hpp).
// Never touches daemon state.
#include <chrono>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <tl/expected.hpp>

#include "blend/blend_tables.hpp"
#include "calibration_job.hpp"
#include "drift/misregistration.hpp"
#include "drift/projector_camera_map.hpp"
#include "drift_fiducial.hpp"
#include "read_fence.hpp"
#include "render/render_setup.hpp"
#include "render/viewer_view.hpp"

namespace procam::daemon {

// What the camera should see: made for one frame (setup and content) and one rig model,
// reused while both stay.
struct DriftReference {
  std::shared_ptr<const render::RenderSetup> setup;
  std::shared_ptr<const cv::Mat> image;
  uint64_t rig_generation = 0;
  std::string camera;
  drift::WorkGrid grid;
  cv::Mat shown;          // the frame's light on the grid, CV_32F, 0..255 for full white
  cv::Mat map;            // grid -> camera pixels
  cv::Mat usable;         // CV_8U of the grid: 0 where the frame is blended with a neighbour's
  double seen_share = 0;  // of the grid the camera sees
  drift::LitSurface lit;  // where the rig model says the framebuffer lights the surface
  // On a mesh: the projector's pixel rays (its pinhole and post-rendering warp).
  std::shared_ptr<const render::PixelRays> rays;
};

struct DriftCheckPlan {
  std::string output;
  CalibrationDevice camera;
  std::shared_ptr<const DriftReference> reference;  // null or stale: made again
  // What a new reference is made from.
  std::shared_ptr<const render::RenderSetup> setup;
  std::shared_ptr<const cv::Mat> image;  // RGBA content of the frame
  uint64_t rig_generation = 0;
  cv::Size framebuffer;  // the rig model's, which the frame must have
  // The display surface: a plane by the projector's collineation with it, or, set, a mesh
  // that the projector's pixel rays meet (through the post-rendering warp of its lens or
  // of `own_mesh`'s pixels, [Raskar02] §4.1.3, as the output draws it).
  geom::PlaneHomography projector_to_plane;
  std::shared_ptr<const geom::MeshIntersector> surface_mesh;
  geom::CameraModel projector_model;
  bool own_mesh = false;
  geom::CameraModel camera_model;
  // The projector's response (light ~ code^gamma): measured, or the one assumed.
  double projector_gamma = blend::kAssumedGamma;
  int frames = 2;  // camera frames averaged
  // How blurred this camera sees the output's frame (work pixels, drift/reference_blur.hpp),
  // fitted by an earlier check; unset: this check fits it.
  std::optional<double> reference_blur;
  // Waited on before the first capture: the device manager's reads of the camera end.
  ReadFence fence;
  // Set: a fiducial check. The frame is shown on `output_device` (its size the
  // framebuffer's) and the capture starts `settle_s` later; the output keeps showing it
  // (the daemon draws the content again). The reference is made all the same, before
  // the frame is shown: the corrections read the camera's map from it.
  std::shared_ptr<const FiducialFrame> fiducial;
  CalibrationDevice output_device;
  double settle_s = 0.1;
  // Set: the frame is a stream's, held on the outputs while the check runs (the worker
  // that draws them, one thread, runs the check): the capture waits until this time, the
  // frame's latency to the camera, which the reference is made in. Only in a check of
  // one output: runDriftChecks measures no other output in a held frame's capture.
  std::optional<std::chrono::steady_clock::time_point> hold_until;
};

struct DriftCheck {
  std::shared_ptr<const DriftReference> reference;
  drift::Misregistration misregistration;
  double seconds = 0;                 // the whole check, capture included
  double reference_s = 0;             // making the reference (0: reused)
  double capture_s = 0;               // the camera frames
  double measure_s = 0;               // the registration
  bool fiducial = false;              // measured from a fiducial frame
  bool blur_fitted = false;           // this check fitted the reference blur
  std::optional<double> fitted_blur;  // what it found (unset: too little to tell)
};

// The plan's reference when it still fits (same setup, content, rig and camera).
bool referenceFits(const DriftCheckPlan& plan);

// The camera's failures (kIo, kNoDevice, ...); the output's, showing a fiducial frame;
// kFailed when the frame cannot be drawn again, it is not the rig model's framebuffer
// size, the camera's frames have another size than the rig model's, it sees too little
// of the frame (under 10 %), a fiducial frame's tags cannot be looked for or a mesh's
// post-rendering warp cannot be made.
tl::expected<DriftCheck, CalibrationFailure> runDriftCheck(const DriftCheckPlan& plan);

// The checks of several outputs by one camera (every plan's): the references made, one
// capture, each output measured in it; one result per plan, in order. A fiducial check
// (the first plan's) runs alone.
std::vector<tl::expected<DriftCheck, CalibrationFailure>> runDriftChecks(
    const std::vector<DriftCheckPlan>& plans);

}  // namespace procam::daemon
