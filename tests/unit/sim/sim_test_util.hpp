#pragma once
// Helpers shared by the virtual-rig tests: shipped scene paths and a small,
// exactly analysable planar rig written as TOML text.
#include <cstdlib>
#include <filesystem>
#include <string>

#include "sim/scene.hpp"

namespace procam::sim::testing {

inline std::filesystem::path sourceDir() {
  const char* dir = std::getenv("PROCAM_SOURCE_DIR");
  return dir ? std::filesystem::path(dir) : std::filesystem::current_path();
}

inline std::filesystem::path scenePath(const std::string& name) {
  return sourceDir() / "tests" / "scenes" / (name + ".toml");
}

// The shipped scenes (tests/scenes), each a case of [Raskar02]'s rendering-path table.
inline const char* const kShippedScenes[] = {"wall_oblique",  "wall_oblique_board", "tiled_wall",
                                             "corner_stereo", "handheld",           "dome3",
                                             "object_box",    "wall_views",         "object_vase"};

// A wall y = 2 facing a projector at the origin (1 m high) that looks straight at
// it, and a camera beside the projector with a parallel optical axis. `camera`
// holds the camera's extra keys (noise, bit depth, gamma ...).
inline std::string flatWallScene(const std::string& camera, double projector_gamma = 2.2) {
  return R"(
[scene]
ambient = 0.05
[[projectors]]
name = "proj"
resolution = [320, 240]
intrinsics = { fx = 300.0, fy = 300.0, cx = 159.5, cy = 119.5 }
pose = { position = [0.0, 0.0, 1.0], yaw_deg = 0.0 }
gamma = )" +
         std::to_string(projector_gamma) +
         R"(
brightness = 3.0
[[cameras]]
name = "cam"
resolution = [240, 180]
intrinsics = { fx = 220.0, fy = 220.0, cx = 119.5, cy = 89.5 }
pose = { position = [0.2, 0.0, 1.0], look_at = [0.2, 2.0, 1.0] }
)" + camera +
         R"(
[[surfaces]]
name = "wall"
type = "plane"
point = [0.0, 2.0, 0.0]
normal = [0.0, -1.0, 0.0]
albedo = 0.7
)";
}

}  // namespace procam::sim::testing
