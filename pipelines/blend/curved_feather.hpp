#pragma once
// Intensity feathering of projectors overlapping on a surface of any shape ([Raskar02]
// §4.1.2, eq. 4.3): the weight of projector m at a surface point is its distance d_m to
// the nearest edge of its own image that another image continues past, over the sum of
// those distances of every projector lighting the point, A_m = d_m / sum_i d_i. A
// projector's image is the part of its frame whose rays meet its surface: a measured
// surface ends short of the frame's edge, and there the image ends. On a
// curved surface there is no common plane, so each distance is taken in its own
// projector's pixels (eq. 4.3 only needs the weights of a point to sum to one and to
// fall to zero at the edge they are measured from); a projector lights a point when the
// point is inside its frame and its own ray through that pixel meets the surface there
// (not hidden behind another part of the surface).
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/intersect.hpp"
#include "render/viewer_view.hpp"

namespace procam::blend {

struct SurfaceProjector {
  const geom::MeshIntersector* surface = nullptr;  // the surface it lights (its measured mesh)
  Mat34 projector = Mat34::Zero();                 // world -> pixels, third row positive in front
  cv::Size size;                                   // framebuffer
  // Framebuffer pixel -> pixel of `projector`'s pinhole image ([Raskar02] §4.1.3); null:
  // the matrix is the projector.
  std::shared_ptr<const render::WarpGrid> post_warp;
};

struct CurvedFeatherOptions {
  int step = 2;                // projector pixels between weight nodes, interpolated between
  double same_point_m = 0.01;  // a ray meeting the surface this close to a point reaches it
};

// Every projector's pixel rays. kInvalidInput for a missing surface, a framebuffer
// size outside [2, 16384] or a singular matrix.
Result<std::vector<render::PixelRays>> surfaceProjectorRays(
    std::span<const SurfaceProjector> projectors);

// Per projector, the weight of every framebuffer pixel (its centre's surface point) as a
// CV_32FC1 image in [0, 1]; 0 where the pixel's ray misses the surface. `drawn`: each
// projector's lookup warp (or none): its image is then also only where the warp draws
// (render::gridSource), so that the weights fall to zero where the frame's content ends.
// kInvalidInput for no projectors, a missing surface, bad sizes, step outside [1, 64], a
// singular matrix or a `drawn` count other than 0 or one per projector.
Result<std::vector<cv::Mat>> curvedFeatherWeights(std::span<const SurfaceProjector> projectors,
                                                  const CurvedFeatherOptions& options = {},
                                                  std::span<const render::WarpGrid> drawn = {});

}  // namespace procam::blend
