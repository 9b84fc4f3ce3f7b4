#pragma once
// Drift seen in a fiducial frame, for content too plain to register (black, one colour):
// the output shows one frame of markers at a low duty cycle and the camera finds their
// corners; each corner found is a tile of the drift check (misregistration.hpp), drawn
// at its framebuffer position and seen where the rig model puts the camera pixel that
// found it: the camera's ray met with the display plane, through the projector's
// collineation with it ([Raskar02] §4.2.1), or, on any surface (a mesh, §4.1), through
// the check's map of the framebuffer into the camera taken back. A moved projector moves
// the corners as it moves content. Pure.
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_homography.hpp"
#include "misregistration.hpp"
#include "projector_camera_map.hpp"

namespace procam::drift {

struct FiducialCorner {
  Vec2 drawn = Vec2::Zero();   // framebuffer pixel the corner was drawn at
  Vec2 camera = Vec2::Zero();  // camera pixel it was found at
};

// `shown`: every corner drawn (framebuffer pixels): those the rig model puts in the
// camera's image count as seen (tiles_seen, tiles_textured); `found`: the corners the
// camera found. The result's too_plain means too few corners were found and agree
// (options.min_tiles). kInvalidInput for non-finite points or a singular collineation.
Result<Misregistration> fiducialMisregistration(std::span<const Vec2> shown,
                                                std::span<const FiducialCorner> found,
                                                const geom::PlaneHomography& projector_to_plane,
                                                const geom::CameraModel& camera,
                                                const MisregistrationOptions& options = {});

// The same on a surface the rig knows as a mesh (or any): `map` (projectorCameraMap on
// `grid`) puts the framebuffer in the camera by the rig model; a corner found at camera
// pixel c was seen at the framebuffer pixel the map puts at c, found from where it was
// drawn (workPixelSeenAt). Corners the map cannot take back are left out. kInvalidInput
// for non-finite points or a map that is not CV_32FC2 of the grid's size.
Result<Misregistration> fiducialMisregistration(std::span<const Vec2> shown,
                                                std::span<const FiducialCorner> found,
                                                const cv::Mat& map, const WorkGrid& grid,
                                                const MisregistrationOptions& options = {});

}  // namespace procam::drift
