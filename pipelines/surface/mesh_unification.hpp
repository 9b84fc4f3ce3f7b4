#pragma once
// Surface mesh unification ([Raskar02] §4.1.3, eq. 4.4): where several projectors'
// meshes (each triangulated on its own) cover the same part of the surface, they do not
// quite agree, and the projectors then disagree about where content lands. Each vertex
// of a projector's mesh, the surface point its pixel u lights, becomes the weighted mean
// of the points every mesh that covers it gives along the ray from the projector's
// centre through it (the pixel's ray, to the calibration's reprojection error),
//   M'(u) = sum_j d_j M_j(u) / sum_k d_k,
// d_j the distance of the point's pixel in projector j to the nearest pixel j's mesh
// does not cover (its image edge or a hole). The mean lies on the pixel's own ray, so the
// projector's calibration still maps the new point to the pixel that lit it: no new
// projection matrix and no post-rendering warp are needed for it.
#include <opencv2/core.hpp>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "surface/surface_model.hpp"

namespace procam::surface {

struct UnifyProjector {
  SurfaceMesh mesh;         // world frame, with each vertex's projector pixel
  Mat34 P = Mat34::Zero();  // world -> projector pixels (third row positive in front)
  cv::Size size;            // framebuffer
};

struct UnifyOptions {
  double max_gap_m = 0.05;  // points farther apart along a ray are other surfaces (a depth step)
  int coverage_scale = 4;   // projector pixels per cell of the coverage raster
};

struct UnifyReport {
  int vertices = 0;      // of all meshes
  int shared = 0;        // vertices another mesh also covers
  double gap_rms_m = 0;  // between the meshes along those vertices' rays, before
  double gap_max_m = 0;
  double gap_after_rms_m = 0;  // the same between the unified meshes
  double gap_after_max_m = 0;
};

// Unifies every mesh in place. kInvalidInput for a framebuffer outside [2, 16384], a
// singular or non-finite P, a mesh whose vertex and pixel counts differ, a pixel that is
// not finite or lies more than a frame's size off the frame, out-of-range face indices or
// options out of range.
Result<UnifyReport> unifyMeshes(std::vector<UnifyProjector>& projectors,
                                const UnifyOptions& options = {});

}  // namespace procam::surface
