#pragma once
// The cheapest drift correction: a projector that moved on a fixed rig gets a new
// collineation with the display plane (and a new pose when the rig knows its pose),
// from the content correspondences the drift check found — no pattern is shown. A
// projector turned or shifted against a plane moves its image on it by a collineation
// ([Raskar02] §4.2.1), so the framebuffer -> framebuffer map from where content was
// drawn to where the rig model sees it land is one homography T, and the projector's
// new collineation is the old one after T. Pure.
#include "core/error.hpp"
#include "geometry/plane_homography.hpp"
#include "misregistration.hpp"
#include "projector_camera_map.hpp"
#include "rig/rig_model.hpp"

namespace procam::drift {

struct ProjectorCorrection {
  rig::RigProjector projector;            // the corrected entry (same name, output, K)
  Mat3 drawn_to_seen = Mat3::Identity();  // T, framebuffer pixels
  double fit_rms_px = 0;                  // of the tiles against T
  double pose_rms_px = -1;                // the new pose's reprojection RMS (-1: no pose)
  int tiles = 0;
};

// `tile`: the collineation the drift check's map used (blend::displayTile of `before`).
// kTooFewPoints under 8 inlier tiles; kIllConditioned when the new pose fits the tiles
// worse than 1 px RMS, kDegenerate when a tile's ray misses the plane; kInvalidInput for
// non-finite input.
Result<ProjectorCorrection> correctProjector(const rig::RigProjector& before,
                                             const geom::PlaneHomography& tile,
                                             const Misregistration& drift);

// On a surface the rig model knows as a mesh (no collineation: [Raskar02] §4.1): the
// content drawn at a tile's framebuffer pixel d was seen where the rig model's pixel s
// lights the surface, `surface.point(s)`, so the moved projector's pixel d lights that
// point; the pose is refitted to those points (as a pinhole to the pinhole pixels the
// drawn ones show, when `surface.to_pinhole` stands for the lens). Tiles whose pixel lights
// no surface (a hole) are left out. The projector needs a pose and intrinsics
// (kInvalidInput without); kTooFewPoints under 8 tiles on the surface; the other errors as
// above.
Result<ProjectorCorrection> correctProjector(const rig::RigProjector& before,
                                             const LitSurface& surface,
                                             const Misregistration& drift);

}  // namespace procam::drift
