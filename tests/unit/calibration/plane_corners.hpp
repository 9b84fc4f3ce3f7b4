#pragma once
// How far a projector's collineation with a plane ([Raskar02] §4.2.4) puts its image
// corners: each framebuffer corner mapped onto the plane by the estimate and seen by the
// TRUE projector; the largest distance in projector pixels. Judged where keystone needs
// it (the keystone bound: 0.5 px).
#include <algorithm>

#include "geometry/camera_model.hpp"
#include "geometry/plane_homography.hpp"

namespace procam::testing {

inline double planeCornerErrorPx(const geom::PlaneHomography& estimate,
                                 const geom::CameraModel& truth) {
  const double w = truth.width, h = truth.height;
  double worst = 0;
  for (const Vec2& c :
       {Vec2(-0.5, -0.5), Vec2(w - 0.5, -0.5), Vec2(w - 0.5, h - 0.5), Vec2(-0.5, h - 0.5)}) {
    const Vec2 ab = (estimate.H * c.homogeneous()).hnormalized();
    auto seen = truth.project(estimate.basis.toWorld(ab));
    if (!seen) return 1e9;
    worst = std::max(worst, (*seen - c).norm());
  }
  return worst;
}

}  // namespace procam::testing
