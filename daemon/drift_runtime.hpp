#pragma once
// The daemon's drift state for recalibrate = "on-drift" (daemon_drift.cpp): per output the
// cameras that watch it, each one's last check, and where the correction stands. Loop
// thread only.
#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "drift_check.hpp"
#include "drift_ladder.hpp"
#include "rig/rig_model.hpp"

namespace procam::daemon {

// What a check was made for: its result is dropped when any of it changed meanwhile.
struct DriftKey {
  std::string output;
  std::string camera;
  std::shared_ptr<const render::RenderSetup> setup;
  std::shared_ptr<const cv::Mat> image;
  std::chrono::steady_clock::time_point shown_at;
  uint64_t rig_generation = 0;
  bool held = false;  // a stream's frame held for the check
};

struct DriftRuntime {
  using Clock = std::chrono::steady_clock;
  // One frame an output showed: its render setup and content, by identity.
  struct Frame {
    std::shared_ptr<const render::RenderSetup> setup;
    std::shared_ptr<const cv::Mat> image;
    bool is(const std::shared_ptr<const render::RenderSetup>& s,
            const std::shared_ptr<const cv::Mat>& i) const {
      return setup && setup == s && image == i;
    }
  };
  // One camera's view of an output: its reference and last check.
  struct View {
    std::shared_ptr<const DriftReference> reference;
    std::optional<drift::Misregistration> last;
    uint64_t last_generation = 0;  // the rig model `last` was measured against
    Clock::time_point checked_at;
    std::optional<Clock::time_point> above;  // drift seen by this camera since
    nlohmann::json timing =
        nullptr;                 // the last check's: {check_s, reference_s, capture_s, measure_s}
    bool last_fiducial = false;  // `last` came from a fiducial frame
    // How blurred this camera sees the output's frames (work pixels), fitted once from
    // content it registered well: the optics, not the frame or the rig model. Fitted again
    // for another framebuffer size or camera focal length (`blur_for`).
    std::optional<double> reference_blur;
    Vec3 blur_for = Vec3::Zero();  // framebuffer width, camera fx, fy when fitted
    // The frame the last content check found too plain to register, and the one a fit of
    // the blur found too little in (null: none): neither is looked at again for it.
    Frame plain, blur_tried;
    bool foundPlain(const std::shared_ptr<const render::RenderSetup>& setup,
                    const std::shared_ptr<const cv::Mat>& image) const {
      return plain.is(setup, image);
    }
  };
  struct Output {
    std::vector<std::string> cameras;  // the fixed cameras that see it
    std::string camera;                // the one of the last check
    std::string unavailable;           // why it is not checked (empty: it is)
    std::map<std::string, View> views;
    uint64_t checks = 0;
    uint64_t failures = 0;
    std::string error;        // the last check's failure
    int passes = 0;           // corrections since the misregistration was last under threshold
    bool unresolved = false;  // the cheap steps did not bring it under: left alone
    uint64_t corrections = 0;
    nlohmann::json last_correction = nullptr;
    // The projector, cameras mounted on it or a camera re-registered, before the
    // corrections since it was last registered: restored when they do not converge.
    std::optional<rig::RigModel> before;
    // The surface mesh files those corrections rewrote (a projector's own mesh keeps the
    // pixels that lit its vertices), as they were: file name -> PLY text.
    std::map<std::string, std::string> before_meshes;
    // Fiducial frames shown for this output, and when the last one was taken off.
    uint64_t fiducial_checks = 0;
    std::optional<Clock::time_point> fiducial_at;
    std::optional<double> fiducial_px;  // the last fiducial check's misregistration
    int quick_fiducials = 0;            // shown since the last one at the period
    // Checks of a stream's frame held on the outputs (on-drift-silent) that counted, and
    // the pace of those begun, as above (from the stream's start).
    uint64_t held_checks = 0;
    std::optional<Clock::time_point> held_at;
    int quick_holds = 0;
    // The scan made since the output was last registered (kNone: none); a check that
    // still finds it drifted escalates at once. Cleared when registered or unresolved.
    DriftScan scan = DriftScan::kNone;
    bool scanning = false;  // its scan is running now
    const View* lastView() const {
      auto it = views.find(camera);
      return it == views.end() ? nullptr : &it->second;
    }
    bool drifted() const {
      return std::any_of(views.begin(), views.end(), [](const auto& v) { return v.second.above; });
    }
    void forgetDrift() {
      for (auto& [name, v] : views) v.above.reset();
    }
    // What was kept to restore is now the rig's own.
    void forgetBefore() {
      before.reset();
      before_meshes.clear();
    }
  };
  int timer = -1;
  bool checking = false;          // a check on the compute worker
  std::string camera_in_use;      // the camera it drives: the device manager keeps off it
  bool writing = false;           // a corrected rig model on its way to rig.json
  bool fiducial_showing = false;  // a fiducial frame is on an output: frames wait
  // A check the frame in flight held back: begun as soon as it is shown (a stream's
  // frames may leave the drift timer no gap of its own).
  bool check_after_frame = false;
  // The fiducial frames, made once per framebuffer size; why there is none.
  std::map<std::pair<int, int>, std::shared_ptr<const FiducialFrame>> fiducial;
  std::string fiducial_unavailable;
  uint64_t next = 0;  // round robin over the outputs
  std::map<std::string, Output> outputs;
};

// Seconds since `t`, by the drift runtime's clock.
inline double secondsSince(DriftRuntime::Clock::time_point t) {
  return std::chrono::duration<double>(DriftRuntime::Clock::now() - t).count();
}

// How long the output's drift has been seen (by the camera that saw it first).
inline double heldFor(const DriftRuntime::Output& o) {
  double held = 0;
  for (const auto& [name, v] : o.views) {
    if (v.above) held = std::max(held, secondsSince(*v.above));
  }
  return held;
}

// A check's figures, as status and the drift events give them.
inline nlohmann::json misregistrationJson(const drift::Misregistration& m) {
  return {
      {"misregistration_px", m.rms_px},
      {"max_px", m.max_px},
      {"confidence", m.confidence},
      {"tiles", {{"seen", m.tiles_seen}, {"textured", m.tiles_textured}, {"used", m.tiles_used}}},
      {"tile_rms_px", m.tile_rms_px},
      {"too_plain", m.too_plain}};
}

}  // namespace procam::daemon
