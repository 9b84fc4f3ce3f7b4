#pragma once
// A print on a flat surface of the virtual rig: a calibration board
// (calib::renderBoard) fixed on a wall, as the factor it multiplies the surface's
// albedo by. The board faces the side the surface's normal points to, upright (its
// top towards world +Z, or +Y on a horizontal surface).
#include <opencv2/core.hpp>
#include <string>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::sim {

struct SurfacePrint {
  std::string board;           // calib::parseBoard form, as written in the scene
  Vec3 center = Vec3::Zero();  // world, on the surface
  cv::Mat factor;              // CV_32F in (0, 1], row 0 at the top of the board
  Vec3 origin = Vec3::Zero();  // world point of the image's outer top-left corner
  Vec3 right = Vec3::UnitX(), down = -Vec3::UnitZ();  // unit, along image x and y
  double metres_per_px = 0;

  // The factor at a point of the surface; 1 off the print.
  float at(const Vec3& point) const;
};

// Printed ink reflects this fraction of what the paper does.
inline constexpr float kInkReflectance = 0.05f;

// The board `board` (calib::parseBoard form) printed at its true size, `px_per_m`
// image pixels per metre, centred on `center` (projected onto the plane through
// `plane_point` with unit normal `normal`). kInvalidInput for a bad board, a scale
// that makes its image exceed 8192 pixels a side, or non-finite input.
Result<SurfacePrint> makeBoardPrint(const std::string& board, const Vec3& center,
                                    const Vec3& plane_point, const Vec3& normal, double px_per_m);

}  // namespace procam::sim
