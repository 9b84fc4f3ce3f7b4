#include "keystone/display_error.hpp"

#include <algorithm>

#include "keystone/keystone_solver.hpp"

namespace procam::keystone {

DisplayError displayError(const geom::Intrinsics& K, const Mat3& R_true,
                          const std::array<Vec2, 4>& corners) {
  const Mat3 to_fb = wallToFramebuffer(K, R_true);
  const Mat3 to_wall = to_fb.inverse();
  std::array<Vec2, 4> w;
  for (int i = 0; i < 4; ++i) w[i] = (to_wall * corners[i].homogeneous()).hnormalized();
  const double left = 0.5 * (w[0].x() + w[3].x()), right = 0.5 * (w[1].x() + w[2].x());
  const double top = 0.5 * (w[0].y() + w[1].y()), bottom = 0.5 * (w[3].y() + w[2].y());
  const std::array<Vec2, 4> ideal = {Vec2(left, top), Vec2(right, top), Vec2(right, bottom),
                                     Vec2(left, bottom)};
  DisplayError e;
  for (int i = 0; i < 4; ++i) {
    const Vec2 p = (to_fb * ideal[i].homogeneous()).hnormalized();
    e.max_corner_px = std::max(e.max_corner_px, (p - corners[i]).norm());
  }
  e.aspect = (right - left) / (top - bottom);
  e.area = (right - left) * (top - bottom);
  return e;
}

}  // namespace procam::keystone
