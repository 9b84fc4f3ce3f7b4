#pragma once
// How far a displayed image is from an upright rectangle, judged with the true
// orientation: the framebuffer corners are cast onto the wall with the true rotation,
// compared with the upright rectangle through their mean edges, and the difference is
// mapped back into framebuffer pixels. Used by the accuracy tests and the bench.
#include <array>

#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::keystone {

struct DisplayError {
  double max_corner_px = 0;  // largest corner distance, framebuffer pixels
  double aspect = 0;         // width / height of the upright rectangle
  double area = 0;           // its area, wall units (wall at distance 1)
};

// `corners`: framebuffer positions TL, TR, BR, BL; `R_true`: wall -> projector.
DisplayError displayError(const geom::Intrinsics& K, const Mat3& R_true,
                          const std::array<Vec2, 4>& corners);

}  // namespace procam::keystone
