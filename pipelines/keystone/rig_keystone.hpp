#pragma once
// Keystone from the rig model on a planar wall ([Raskar02] §3.2.5, §4.2.1): the
// projector's collineation with the wall plane (found by calibration, route (b′))
// gives its image on the wall; the content is shown in the largest rectangle of
// its aspect, upright (world +Z up projected into the wall), inside that image; the
// pre-warp is content -> wall rectangle -> framebuffer. No tilt sensor and no
// projector intrinsics are needed.
#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/plane_homography.hpp"
#include "keystone/keystone_solver.hpp"

namespace procam::keystone {

struct RigKeystoneProblem {
  geom::PlaneHomography projector_to_plane;  // framebuffer pixels -> plane basis
  int width = 0, height = 0;                 // framebuffer size
  int content_width = 0, content_height = 0;
  InscribeOptions inscribe;
};

// The solution's wall coordinates are metres in the plane's upright basis
// (geom::uprightBasis, seen from the side u x v points to) at the stored origin.
// kInvalidInput for bad sizes, a non-orthonormal basis or a non-finite or singular
// collineation; kDegenerate for a horizontal plane (no upright direction) and the
// errors of solveOnWall (a framebuffer corner beyond the wall's horizon).
Result<KeystoneSolution> solveRigKeystone(const RigKeystoneProblem& problem);

}  // namespace procam::keystone
