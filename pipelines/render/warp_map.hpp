#pragma once
// Backward warp maps: for every output pixel, the source-image coordinate to sample
// (ARCHITECTURE.md's pixel convention). Built once when the geometry changes and applied to
// every frame (precomputed maps). Entries outside the source footprint sample as black;
// kOutside marks pixels that no source pixel reaches. Maps hold float32 coordinates:
// per-pixel render data, with the error against double bounded in tests.
#include <opencv2/core.hpp>
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::render {

inline constexpr float kOutside = -65536.0f;

struct WarpMap {
  cv::Mat xy;  // CV_32FC2, output size; (x, y) source coordinates or (kOutside, kOutside)
  cv::Size size() const { return xy.size(); }
};

// The post-rendering warp grid of [Raskar02] §4.1.3: nodes on a regular lattice of output
// pixels, each holding the source coordinate it must show. Between nodes the map is
// piecewise linear over two triangles per cell, split along the diagonal from node
// (i, j) to (i+1, j+1) — the "multiple textured triangles" of [Raskar02], identical on
// the CPU and in GL.
struct WarpGrid {
  int cols = 0, rows = 0;      // node counts, >= 2 each
  Vec2 origin = Vec2::Zero();  // output pixel of node (0, 0)
  Vec2 step = Vec2(8.0, 8.0);  // output pixels between nodes, > 0
  std::vector<Vec2> source;    // rows * cols source coordinates, row-major
  Vec2 node(int i, int j) const { return origin + Vec2(i * step.x(), j * step.y()); }
  const Vec2& at(int i, int j) const { return source[static_cast<size_t>(j) * cols + i]; }
};

// A grid over a framebuffer with nodes about `step` pixels apart, the first on pixel
// centre 0 and the last on the last pixel centre of each axis, every source kOutside.
// Needs size >= 2 x 2 and step >= 1.
WarpGrid framebufferGrid(cv::Size size, int step);

// Map of an output image related to the source by dst ~ H * src ([Raskar02] §4.2.1 eq. 4.6).
// kInvalidInput for non-finite H or empty size, kDegenerate when H is singular.
Result<WarpMap> homographyMap(const Mat3& H, cv::Size output_size);

// Dense map of a warp grid over an output image; pixels outside the grid, or in a
// triangle with a kOutside node, are kOutside.
Result<WarpMap> gridMap(const WarpGrid& grid, cv::Size output_size);

// The grid's source coordinate at an output pixel (gridMap's, in double precision);
// nullopt where gridMap gives kOutside, and for a grid gridMap refuses.
std::optional<Vec2> gridSource(const WarpGrid& grid, const Vec2& pixel);

// The map of applying `first` then `second`: result(m) = first(second(m)), `first`
// sampled bilinearly (nearest valid entry next to a kOutside region).
// kInvalidInput when either map is empty.
Result<WarpMap> composeMaps(const WarpMap& first, const WarpMap& second);

// Identity map (every output pixel samples itself).
WarpMap identityMap(cv::Size size);

}  // namespace procam::render
