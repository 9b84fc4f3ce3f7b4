#pragma once
// The rig model's projectors as tiles of one planar display: each projector's
// collineation with the display plane ([Raskar02] §4.2.1) — the one calibration route
// (b′) measured (`plane_homography`), or, for a projector with intrinsics and a pose
// (route (a)) and a planar surface, K [R u | R v | R o + t] inverted (ideal pixels: the
// lens distortion is not in a collineation) — and its measured response
// (rig.json `photometric`).
#include <nlohmann/json.hpp>
#include <optional>

#include "blend/response.hpp"
#include "blend/tiled_display.hpp"
#include "core/error.hpp"
#include "rig/rig_model.hpp"

namespace procam::blend {

// kNotFound when the rig gives the projector no collineation with a plane (no
// plane_homography, and no pose or no planar surface); errors of planeToImage.
Result<DisplayTile> displayTile(const rig::RigProjector& projector, const rig::RigSurface& surface);

// The response the projector's rig.json `photometric` record describes (response_gamma
// in [1, 4], white above black), or nullopt; with its brightness across the frame when
// the record holds a valid one of the projector's framebuffer size (brightness_map.hpp).
std::optional<ProjectorResponse> projectorResponse(const rig::RigProjector& projector);

}  // namespace procam::blend
