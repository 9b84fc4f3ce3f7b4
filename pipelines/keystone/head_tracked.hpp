#pragma once
// Head-tracked rendering on a planar display with an oblique projector, in one pass
// ([Raskar02] §4.2.1-4.2.3, Appendix B):
//  1. P_T: off-axis frustum from the viewer T through the axis-aligned rectangle S on
//     the display plane that bounds the projector's keystoned image (§4.2.1);
//  2. A: the collineation from P_T's normalised image to the projector's, induced by the
//     plane (eq. 4.6); independent of T because S is fixed;
//  3. A'4x4 · P_T with the depth row scaled by 1 - |a31| - |a32| (eq. 4.10), which keeps
//     depth in [-1, 1] for points inside S's frustum (eq. 4.9).
// Normalised coordinates here are OpenGL's clip/NDC space (x right, y up, z in [-1, 1]
// from near to far), since that is where the depth buffer lives. Framebuffer pixels
// follow ARCHITECTURE.md (pixel centres at integers, y down).
#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::keystone {

// Rectangle on the display plane: lower-left corner, unit orthogonal axes u (right) and
// v (up); the viewer is on the side of u × v.
struct DisplayRect {
  Vec3 corner = Vec3::Zero();
  Vec3 u = Vec3::UnitX();
  Vec3 v = Vec3::UnitY();
  double width = 1, height = 1;

  Vec3 center() const { return corner + 0.5 * width * u + 0.5 * height * v; }
};

// S of §4.2.1: the rectangle with axes (u, v) through `origin` that bounds the
// projector's image (framebuffer pixel edges) on the plane. `P` maps world -> pixels.
// kDegenerate when a corner ray misses the plane.
Result<DisplayRect> boundingDisplayRect(const Mat34& P, int width, int height, const Vec3& origin,
                                        const Vec3& u, const Vec3& v);

// P_T: world -> clip coordinates (glFrustum · view). kDegenerate when the eye is not
// in front of S; kInvalidInput for 0 < near < far violated or a bad rectangle.
Result<Mat4> offAxisProjection(const Vec3& eye, const DisplayRect& S, double near, double far);

// A (eq. 4.6): P_T's NDC (x, y) -> projector NDC (x, y), normalised so a33 = 1.
Result<Mat3> planeCollineation(const Mat34& P, int width, int height, const DisplayRect& S);

// A'4x4 (eq. 4.10). kIllConditioned when 1 - |a31| - |a32| <= 0 (eq. 4.9 cannot hold).
Result<Mat4> singlePassMatrix(const Mat3& A);

// Framebuffer pixel <-> NDC of a width x height framebuffer.
Vec2 ndcToPixel(const Vec2& ndc, int width, int height);
Vec2 pixelToNdc(const Vec2& pixel, int width, int height);

struct HeadTrackedPath {
  Mat4 P_T = Mat4::Identity();
  Mat3 A = Mat3::Identity();
  Mat4 single_pass = Mat4::Identity();  // A'4x4 · P_T
};

Result<HeadTrackedPath> headTrackedPath(const Vec3& eye, const DisplayRect& S, double near,
                                        double far, const Mat34& P, int width, int height);

}  // namespace procam::keystone
