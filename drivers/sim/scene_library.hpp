#pragma once
// The shipped scenes (tests/scenes/*.toml), embedded at build time so installed
// tools and the daemon find them by name without the source tree.
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "sim/scene.hpp"

namespace procam::sim {

std::vector<std::string> builtinSceneNames();

// An existing file path is loaded from disk (meshes relative to it); anything else
// is looked up among the embedded scenes by name ("wall_oblique" or
// "wall_oblique.toml"). kNotFound lists the names that exist.
Result<Scene> resolveScene(std::string_view name_or_path);

}  // namespace procam::sim
