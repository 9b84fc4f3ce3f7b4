#pragma once
// Image content on a non-planar display for a viewer whose eye is known ([Raskar02]
// §3.2.3, §4.1.5): the content is the image the viewer should see. Its image plane is a
// pinhole view from the eye looking at the surface point at the centre of the projector's
// image, with world +Z up, and the content fills the largest upright rectangle of its
// aspect inside the projector's footprint as the eye sees it. A projector pixel then shows
// the content pixel where the eye's ray through that pixel's surface point crosses the
// plane: the two-pass path draws exactly that (§3.2.3), the lookup warp samples it on a
// grid (§4.1.5).
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/intersect.hpp"
#include "keystone/inscribed_rect.hpp"
#include "render/warp_map.hpp"

namespace procam::render {

// The rays of a projector's pixels: centre of projection and world directions.
struct PixelRays {
  Mat3 Minv;  // inverse of the matrix's left 3x3
  Vec3 centre;
  // Framebuffer pixel -> pixel of the matrix's pinhole image ([Raskar02] §4.1.3,
  // render/post_render_warp.hpp); null: the matrix is the projector.
  std::shared_ptr<const WarpGrid> post_warp;
  Mat3 M = Mat3::Identity();  // the matrix's left 3x3

  // The pinhole pixel a framebuffer pixel shows (past the warp's grid, the shift at its
  // nearest edge).
  Vec2 toPinhole(const Vec2& pixel) const;
  // The framebuffer pixel that shows a pinhole pixel (the warp inverted by fixed-point
  // steps: it moves pixels by a smooth field of a few pixels).
  Vec2 toFramebuffer(const Vec2& pinhole) const;
  // The framebuffer pixel whose ray passes through X; nullopt behind the projector.
  std::optional<Vec2> framebufferPixelOf(const Vec3& X) const;
  geom::Ray through(double x, double y) const {
    const Vec2 m = toPinhole(Vec2(x, y));
    return {centre, (Minv * m.homogeneous()).normalized()};
  }
};

// kInvalidInput for a non-finite or singular projector matrix.
Result<PixelRays> pixelRays(const Mat34& projector,
                            std::shared_ptr<const WarpGrid> post_warp = nullptr);

// The eye's frame looking along `forward`: rows x right, y down, z forward, world +Z
// up. kDegenerate when `forward` is (nearly) vertical.
Result<Mat3> uprightEyeRotation(const Vec3& forward);

// World -> content pixels for an eye at `eye` turned by `R` (uprightEyeRotation) whose
// content fills `rect` on the plane z = 1 (x right, y up): content pixel edges on the
// rectangle's edges.
Mat34 contentViewMatrix(const Mat3& R, const Vec3& eye, const keystone::AxisRect& rect,
                        cv::Size content);

// projector: world -> projector pixels (third row positive in front). Returns the
// world -> content pixel matrix (RenderSetup::viewer). kDegenerate when the centre ray
// misses the surface, too little of the footprint is seen, or part of it lies behind the
// eye; kInvalidInput for empty sizes or non-finite input.
Result<Mat34> viewerContentMatrix(const geom::MeshIntersector& surface, const Mat34& projector,
                                  cv::Size projector_size, const Vec3& eye, cv::Size content_size);

// A lookup warp to any content projection: nodes every `step` framebuffer pixels
// (framebufferGrid) holding to_content(the surface point the node's ray meets), kOutside
// where the ray misses the surface or to_content gives nothing. kInvalidInput for a
// size under 2 x 2, a step under 1 or a singular projector matrix.
Result<WarpGrid> lookupGridThrough(
    const geom::MeshIntersector& surface, const Mat34& projector, cv::Size projector_size, int step,
    std::shared_ptr<const WarpGrid> post_warp,
    const std::function<std::optional<Vec2>(const Vec3&)>& to_content);

// The lookup warp for that viewer: nodes every `step` projector pixels (the last row and
// column on the frame's edge) holding the content pixel each shows; nodes whose ray misses
// the surface or lands behind the eye hold kOutside.
// `post_warp`: the projector's post-rendering warp, as pixelRays takes it.
Result<WarpGrid> lookupGridForViewer(const geom::MeshIntersector& surface, const Mat34& projector,
                                     cv::Size projector_size, const Mat34& viewer, int step = 8,
                                     std::shared_ptr<const WarpGrid> post_warp = nullptr);

}  // namespace procam::render
