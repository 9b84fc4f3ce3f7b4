#pragma once
// Two-pass projective texture over a surface mesh ([Raskar02] §3.2.3, §4.1.1): the desired
// image for a viewer is projected from the viewer's centre onto the display-surface mesh,
// and the mesh is seen from the projector. For a fixed mesh, projector and viewer this is
// a fixed map from projector pixels to desired-image pixels, built here in double.
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "render/warp_map.hpp"

namespace procam::render {

struct SurfaceMesh {
  std::vector<Vec3> vertices;                 // world, metres
  std::vector<std::array<int, 3>> triangles;  // vertex indices
};

// projector, viewer: 3x4 world -> pixel matrices whose third row is positive in front of
// the device. Nearest surface wins per projector pixel (depth test). Triangles with a
// vertex behind the projector are skipped (display surfaces lie in front of it). Pixels
// whose surface point is behind the viewer, or that no triangle covers, are kOutside.
// kInvalidInput for bad indices, non-finite input or an empty output size.
Result<WarpMap> projectiveTextureMap(const SurfaceMesh& mesh, const Mat34& projector,
                                     const Mat34& viewer, cv::Size output_size);

// 4x4 matrix from world to homogeneous pixels with depth: rows (x w, y w, z w, w) with
// z = -1 at depth near_w and +1 at far_w, w = projector.row(2) * X. kInvalidInput unless
// 0 < near_w < far_w.
Result<Mat4> pixelProjectionWithDepth(const Mat34& projector, double near_w, double far_w);

// Smallest and largest depth w of the mesh's vertices as seen by the projector.
Result<std::array<double, 2>> depthRange(const SurfaceMesh& mesh, const Mat34& projector);

}  // namespace procam::render
