#pragma once
// Inverts a decoded camera -> projector map on a projector grid: for every projector
// node (i*step, j*step) the sub-pixel camera point that sees it. A local affine fit
// of camera position against decoded projector position over the node's
// neighbourhood averages the decoder's quantisation and noise ([Raskar02] §4.1.1 "for
// each projector pixel (u, v) ... a corresponding illuminated 3D surface point").
#include <cstdint>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "structured_light/decoder.hpp"

namespace procam::surface {

struct SampleOptions {
  int step = 8;  // projector pixels between nodes
  // Neighbourhood half-width in projector pixels; at least step/2 and 1.5 times the
  // projector pixels one camera pixel spans (measured from the map, 90th percentile), so that every
  // neighbourhood holds several camera pixels. With Gray codes of cell k (pattern
  // step k) use at least k, so that the neighbourhood spans several decoded cells.
  double radius = 2.0;
  int min_pixels = 6;         // decoded camera pixels needed in a neighbourhood
  double min_confidence = 0;  // ignore decoded pixels below this confidence
};

struct ProjectorSamples {
  int step = 0;
  int nodes_x = 0, nodes_y = 0;     // grid of the projector: node (i, j) at (i*step, j*step)
  std::vector<std::int32_t> index;  // nodes_y * nodes_x: sample index or -1
  Points2 projector;                // node position, projector pixels
  Points2 camera;                   // camera pixel seeing it (distorted, as captured)

  std::int32_t at(int i, int j) const { return index[static_cast<std::size_t>(j) * nodes_x + i]; }
};

// kInvalidInput for a bad step or decoded map; an empty result is not an error.
Result<ProjectorSamples> sampleProjectorGrid(const sl::Decoded& decoded, int projector_width,
                                             int projector_height, const SampleOptions& options);

}  // namespace procam::surface
