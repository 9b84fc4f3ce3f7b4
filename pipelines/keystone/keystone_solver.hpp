#pragma once
// Keystone correction for a projector in front of a vertical wall ([Raskar02] §3.2.5): the
// projector's image on the wall is a keystoned quadrilateral; the content is shown in the
// largest rectangle of its aspect ratio, aligned with gravity, inside it; the pre-warp is
// the homography content pixels -> framebuffer pixels. Translation does not matter
// (§6.2.2): the wall is put at distance 1 along the wall frame's Y (orientation.hpp).
#include <array>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "keystone/inscribed_rect.hpp"

namespace procam::keystone {

struct KeystoneProblem {
  geom::Intrinsics K;                         // projector intrinsics (framebuffer pixels)
  int width = 0, height = 0;                  // framebuffer size
  Mat3 R = Mat3::Identity();                  // wall frame -> projector (orientation.hpp)
  int content_width = 0, content_height = 0;  // content pixels; aspect = their ratio
  InscribeOptions inscribe;
};

struct KeystoneSolution {
  Mat3 H = Mat3::Identity();  // content pixels -> framebuffer pixels, H(2,2) = 1
  // Framebuffer positions of the content's outer corners (pixel edges (-0.5, -0.5) ...):
  // top-left, top-right, bottom-right, bottom-left.
  std::array<Vec2, 4> corners;
  // The projector's image on the wall, wall coordinates (X right, Z up), corners of the
  // framebuffer in the same order.
  std::array<Vec2, 4> wall_quad;
  AxisRect rect;                                // the chosen rectangle, wall coordinates
  Mat3 wall_to_framebuffer = Mat3::Identity();  // (X, Z, 1) -> framebuffer pixels
  // Linear size of the corrected image relative to the uncorrected one:
  // sqrt(rectangle area / quadrilateral area).
  double scale = 0;
};

// kInvalidInput for bad sizes/intrinsics/rotation; kDegenerate when part of the
// framebuffer does not reach the wall (a corner ray is parallel to it or points away).
Result<KeystoneSolution> solveKeystone(const KeystoneProblem& problem);

// The same from the wall's collineation with the framebuffer, however it was found
// (wall coordinates X right, Y up, any unit; [Raskar02] §4.2.1): the largest upright
// rectangle of the content's aspect inside the framebuffer's image on the wall.
// kInvalidInput for bad sizes or a non-finite or singular collineation; kDegenerate
// when a framebuffer corner maps to or beyond the wall's horizon (its homogeneous
// wall coordinate w <= 1e-6 |(x, y, w)|).
Result<KeystoneSolution> solveOnWall(const Mat3& wall_to_framebuffer, int width, int height,
                                     int content_width, int content_height,
                                     const InscribeOptions& inscribe = {});

// Wall coordinates (X, Z) -> framebuffer pixels: K [r1 r3 r2] (wall plane Y = 1).
Mat3 wallToFramebuffer(const geom::Intrinsics& K, const Mat3& R);

}  // namespace procam::keystone
