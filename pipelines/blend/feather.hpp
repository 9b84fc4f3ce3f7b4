#pragma once
// Intensity feathering of overlapping projectors ([Raskar02] §4.1.2, eq. 4.3): the
// weight of projector m at a wall point is its distance d_m to the nearest edge of its
// own image on the wall, over the sum of those distances of every projector whose
// image holds the point: A_m = d_m / sum_i d_i. Distances are taken on the wall (one
// raster for all projectors: the common space eq. 4.3 takes in a camera image), so the
// weights of a point sum to one. Only image edges that another image continues past
// count: the union's outer boundary is no seam, and weighing by the distance to it
// would make the weights jump where two images end side by side (measured on a 2x2
// wall: steps of 0.3 between neighbouring pixels inside the display). The weights are
// linear light; the output's weight lookup table (render/final_stage.hpp) turns them
// into code values through the projector's response.
#include <array>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::blend {

struct FeatherTile {
  std::array<Vec2, 4> footprint;  // framebuffer corners on the wall, in order
  Mat3 plane_to_framebuffer;      // wall (x, y, 1) -> framebuffer pixels
  int width = 0, height = 0;      // framebuffer size
};

// Distance from `p` to the nearest edge of the convex quad `q`, 0 outside it.
double insideDistance(const std::array<Vec2, 4>& q, const Vec2& p);

// Per tile, the weight of every framebuffer pixel (its centre's wall point) as a
// CV_32FC1 image in [0, 1]; distances on a wall raster of `raster_cells` along the
// union's longer side, interpolated bilinearly. kInvalidInput for no tiles, bad sizes,
// a raster_cells outside [64, 8192] or a singular plane_to_framebuffer.
Result<std::vector<cv::Mat>> featherWeights(std::span<const FeatherTile> tiles,
                                            int raster_cells = 1024);

// The weights as an 8-bit alpha mask (round(255 w)).
cv::Mat alphaMask(const cv::Mat& weights);

}  // namespace procam::blend
