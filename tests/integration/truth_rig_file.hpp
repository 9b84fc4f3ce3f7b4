#pragma once
// A known rig for the tests that want one: the scene's truth as a rig model
// (what `procam-sim truth --rig-json` writes), handed to procamd explicitly with
// `--rig FILE`. procamd itself never reads the simulator's truth.
#include <fstream>
#include <string>

#include "daemon_harness.hpp"
#include "rig/rig_model.hpp"
#include "sim/scene_library.hpp"
#include "sim/truth_rig.hpp"

namespace procam::itest {

enum class TruthParts {
  kAll,          // cameras, projectors (with tilt mounts), surface plane, viewer
  kCamerasOnly,  // what an offline camera calibration gives: calibrate finds the rest
  // Cameras at several positions: every camera's intrinsics, a pose for the first one
  // only (the others calibrated alone from board views).
  kFirstCameraPosed,
};

// Writes the truth of `scene` (a shipped name or a file) at time 0 as `name` in
// `dir`; returns its path, or "" (with a test failure) when the scene is unusable.
inline std::string truthRigFile(const TempDir& dir, const std::string& scene,
                                TruthParts parts = TruthParts::kAll,
                                const std::string& name = "truth-rig.json") {
  auto s = sim::resolveScene(scene);
  if (!s) {
    ADD_FAILURE() << s.error().message;
    return "";
  }
  auto rig = sim::truthRig(*s, 0.0);
  if (!rig) {
    ADD_FAILURE() << rig.error().message;
    return "";
  }
  if (parts != TruthParts::kAll) {
    rig->projectors.clear();
    rig->surface = {};
    rig->viewer = {};
  }
  for (std::size_t c = 1; parts == TruthParts::kFirstCameraPosed && c < rig->cameras.size(); ++c) {
    rig->cameras[c].pose_known = false;
    rig->cameras[c].model.pose = geom::Pose{};
  }
  dir.write(name, rig::rigToJson(*rig).dump(2) + "\n");
  return dir.file(name);
}

// `procamd --sim SCENE --rig <its truth>`.
inline DaemonProcess::Launch simWithTruth(const TempDir& dir, const std::string& scene,
                                          TruthParts parts = TruthParts::kAll) {
  return DaemonProcess::Launch{
      {"--sim", scene, "--rig", truthRigFile(dir, scene, parts)}, {}, -1, true};
}

}  // namespace procam::itest
