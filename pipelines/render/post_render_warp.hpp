#pragma once
// The post-rendering warp of [Raskar02] §4.1.3 (eq. 4.5). A projector drawn through the
// pinhole matrix P' of its calibration puts the surface point M' that its pixel m lit
// during structured light at m'' = P' M', not at m: the pinhole leaves out the lens, and
// the unified surface (eq. 4.4) moved M'. The warp sends every framebuffer pixel m to the
// pixel m'' of the pinhole's image, so that what the pinhole drew at m'' is shown at m:
// measured, from the pairs (m, M') of the surface mesh interpolated over its triangles in
// projector space; or, with no pairs, from the projector's lens model (m'' = the ideal
// pixel of m). The two-pass path draws it after the pinhole (RenderSetup::post_warp), and
// the lookup warps and blend weights cast pixel rays through it (PixelRays::post_warp).
#include <memory>
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/intersect.hpp"
#include "render/warp_map.hpp"

namespace procam::render {

struct PostRenderWarp {
  enum class Source { kMeasured, kLens };
  Source source = Source::kMeasured;
  WarpGrid grid;      // framebuffer pixel -> pixel of the pinhole's image
  double rms_px = 0;  // |m'' - m| over the measured vertices (the lens model: over the nodes)
  double max_px = 0;
  int points = 0;  // measured vertices used; 0 for the lens model
};

// Pixels moved further than this (RMS) are not a lens's or a unified surface's doing.
inline constexpr double kMaxMeasuredShiftPx = 50;

// `mesh`: its vertices (world) with `uv`, the projector pixel that lit each. Nodes every
// `step` framebuffer pixels (render::framebufferGrid); a node no triangle covers takes the
// value of the nearest covered one. kInvalidInput without uv for every vertex, for a face
// out of range, a bad size or step or a non-finite P; kTooFewPoints when no triangle lies
// in front of P; kDegenerate when the pixels move more than kMaxMeasuredShiftPx RMS.
Result<PostRenderWarp> measuredPostRenderWarp(const geom::TriangleMesh& mesh, const Mat34& P,
                                              cv::Size size, int step = 8);

// From the projector's lens model alone (its K and distortion). Nodes beyond the model's
// fold take the nearest node's value. kInvalidInput for a bad size or step.
Result<PostRenderWarp> lensPostRenderWarp(const geom::CameraModel& projector, int step = 8);

// A projector's warp for drawing through `projector`'s pinhole matrix: measured when
// `own_mesh` (the projector's own measured mesh, not one shared by several) carries the
// pixels that lit its vertices, else from the lens model when it has distortion; nullptr
// when neither (the pinhole is the projector). Errors as above.
Result<std::shared_ptr<const PostRenderWarp>> projectorPostRenderWarp(
    const geom::CameraModel& projector, const geom::TriangleMesh* own_mesh, int step = 8);

}  // namespace procam::render
