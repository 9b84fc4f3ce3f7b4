#pragma once
// The virtual camera's documented 2 x 2 rotated-grid sample positions within a pixel
// (sim/renderer.hpp), restated for the tests that rebuild a pixel from rays.
#include "core/types.hpp"

namespace procam::sim::testing {

inline const Vec2 kSampleOffsets[4] = {
    {-0.375, -0.125}, {0.125, -0.375}, {-0.125, 0.375}, {0.375, 0.125}};

}  // namespace procam::sim::testing
