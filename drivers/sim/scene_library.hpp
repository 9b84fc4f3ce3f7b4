#pragma once
// The shipped scenes (tests/scenes/*.toml), embedded at build time so installed
// tools and the daemon find them by name without the source tree.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "sim/scene.hpp"

namespace procam::sim {

std::vector<std::string> builtinSceneNames();

// The TOML text of a built-in scene ("wall_oblique"), for a caller that adds to it
// (events, another camera); nullopt for an unknown name.
std::optional<std::string_view> builtinSceneText(std::string_view name);

// An existing file path is loaded from disk (meshes relative to it); anything else
// is looked up among the embedded scenes by name ("wall_oblique" or
// "wall_oblique.toml"). kNotFound lists the names that exist.
Result<Scene> resolveScene(std::string_view name_or_path);

}  // namespace procam::sim
