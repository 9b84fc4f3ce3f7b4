#include "sim/surface_print.hpp"

#include <cmath>

#include "calibration/board.hpp"

namespace procam::sim {

float SurfacePrint::at(const Vec3& point) const {
  const Vec3 local = point - origin;
  const double x = local.dot(right) / metres_per_px, y = local.dot(down) / metres_per_px;
  if (!(x >= 0 && y >= 0 && x < factor.cols && y < factor.rows)) return 1.f;
  return factor.at<float>(static_cast<int>(y), static_cast<int>(x));
}

Result<SurfacePrint> makeBoardPrint(const std::string& board, const Vec3& center,
                                    const Vec3& plane_point, const Vec3& normal, double px_per_m) {
  if (!center.allFinite() || !plane_point.allFinite() || !(normal.norm() > 0) ||
      !std::isfinite(px_per_m) || !(px_per_m > 0))
    return fail(ErrorCode::kInvalidInput, "board print: non-finite or zero input");
  auto spec = calib::parseBoard(board);
  if (!spec) return fail(ErrorCode::kInvalidInput, spec.error().message);
  auto extent = calib::boardExtent(*spec);
  if (!extent) return tl::unexpected(extent.error());
  constexpr double kMaxSide = 8192;
  if (extent->width * px_per_m > kMaxSide || extent->height * px_per_m > kMaxSide)
    return fail(ErrorCode::kInvalidInput,
                "board print: over 8192 pixels a side at " + std::to_string(px_per_m) + " px/m");
  auto image = calib::renderBoard(*spec, px_per_m);
  if (!image) return fail(ErrorCode::kInvalidInput, image.error().message);
  SurfacePrint p;
  p.board = board;
  const Vec3 n = normal.normalized();
  p.center = center - n * n.dot(center - plane_point);
  const Vec3 up_hint = std::abs(n.z()) > 0.9 ? Vec3::UnitY() : Vec3::UnitZ();
  p.right = up_hint.cross(n).normalized();
  p.down = -n.cross(p.right);
  image->convertTo(p.factor, CV_32F, (1.0 - kInkReflectance) / 255.0, kInkReflectance);
  // The image's scale from the board's true size: renderBoard rounds its squares to
  // whole pixels.
  p.metres_per_px = extent->width / image->cols;
  p.origin = p.center - 0.5 * image->cols * p.metres_per_px * p.right -
             0.5 * image->rows * p.metres_per_px * p.down;
  return p;
}

}  // namespace procam::sim
