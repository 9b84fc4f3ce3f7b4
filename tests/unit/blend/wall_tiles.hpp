#pragma once
// Synthetic projectors on the wall y = 3 (normal -Y, seen from the room, y < 3) and
// their collineations with it, as calibration route (b′) gives them.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <vector>

#include "blend/tiled_display.hpp"
#include "geometry/camera_model.hpp"

namespace procam::testing {

struct WallProjector {
  geom::CameraModel model;
  blend::DisplayTile tile;
};

inline const geom::Plane kWall{Vec3(0, 1, 0), -3.0};

// A 1280x800 projector at `position` looking along +Y turned by yaw (right) and pitch
// (up) in degrees, its collineation with the wall expressed in a basis with origin
// `basis_origin` (tiles may be calibrated in bases of their own).
inline WallProjector wallProjector(const Vec3& position, double yaw_deg, double pitch_deg,
                                   const Vec3& basis_origin = Vec3(0, 3, 1.5)) {
  constexpr double kDeg = std::numbers::pi / 180;
  WallProjector p;
  p.model.width = 1280;
  p.model.height = 800;
  p.model.K = {1500, 1500, 639.5, 399.5, 0};
  const Vec3 dir(std::sin(yaw_deg * kDeg) * std::cos(pitch_deg * kDeg),
                 std::cos(yaw_deg * kDeg) * std::cos(pitch_deg * kDeg), std::sin(pitch_deg * kDeg));
  p.model.pose = geom::Pose::lookAt(position, position + dir, Vec3::UnitZ());
  auto basis = geom::uprightBasis(kWall, Vec3(0, 0, 1.5), basis_origin);
  EXPECT_TRUE(basis);
  auto to_image = geom::planeToImage(p.model.K, p.model.pose, *basis);
  EXPECT_TRUE(to_image);
  p.tile.projector_to_plane = {*basis, to_image->inverse()};
  p.tile.width = p.model.width;
  p.tile.height = p.model.height;
  return p;
}

// A 2x2 wall: projectors 1.45 m apart sideways and 0.9 m vertically, 2 m from the
// wall (images about 1.7 m x 1.07 m), each turned one or two degrees towards the
// middle: overlaps of about 0.3 m across and 0.25 m down. Bases differ per tile.
inline std::vector<WallProjector> twoByTwo() {
  return {wallProjector({-0.725, 1.0, 1.95}, 2, -1),
          wallProjector({0.725, 1.0, 1.95}, -1, -2, Vec3(1, 3, 0)),
          wallProjector({-0.725, 1.0, 1.05}, 1, 2, Vec3(-2, 3, 2)),
          wallProjector({0.725, 1.0, 1.05}, -2, 1)};
}

inline std::vector<blend::DisplayTile> tilesOf(const std::vector<WallProjector>& ps) {
  std::vector<blend::DisplayTile> t;
  for (const auto& p : ps) t.push_back(p.tile);
  return t;
}

}  // namespace procam::testing
