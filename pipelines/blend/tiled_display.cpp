#include "blend/tiled_display.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "blend/coverage_raster.hpp"

namespace procam::blend {
namespace {

// Inside a convex quad (either winding), boundary included.
bool insideQuad(const std::array<Vec2, 4>& q, const Vec2& p) {
  int sign = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec2 a = q[i], b = q[(i + 1) % 4];
    const double c = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    const int s = c > 1e-12 ? 1 : c < -1e-12 ? -1 : 0;
    if (s == 0) continue;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return true;
}

}  // namespace

Mat3 contentToWall(const keystone::AxisRect& rect, int content_width, int content_height) {
  const double sx = 2 * rect.half_width / content_width;
  const double sy = 2 * rect.half_height / content_height;
  const double left = rect.centre.x() - rect.half_width;
  const double top = rect.centre.y() + rect.half_height;
  Mat3 m;
  m << sx, 0, left + 0.5 * sx, 0, -sy, top - 0.5 * sy, 0, 0, 1;
  return m;
}

Result<TiledDisplay> solveTiledDisplay(std::span<const DisplayTile> tiles, int content_width,
                                       int content_height, const TiledDisplayOptions& options) {
  if (tiles.empty()) return fail(ErrorCode::kInvalidInput, "a display needs at least one tile");
  if (content_width < 1 || content_height < 1 || content_width > 65536 || content_height > 65536)
    return fail(ErrorCode::kInvalidInput, "content size out of range");
  if (options.raster_cells < 16 || options.raster_cells > 8192)
    return fail(ErrorCode::kInvalidInput, "raster_cells outside [16, 8192]");
  TiledDisplay out;
  const geom::PlaneBasis& first = tiles.front().projector_to_plane.basis;
  const Vec3 n = first.normal();
  if (!first.origin.allFinite() || !(n.norm() > 0.5))
    return fail(ErrorCode::kInvalidInput, "the first tile's plane basis is not valid");
  const geom::Plane plane{n.normalized(), -n.normalized().dot(first.origin)};
  auto upright = geom::uprightBasis(plane, first.origin + plane.n, first.origin);
  if (!upright) return tl::unexpected(upright.error());
  out.basis = *upright;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const DisplayTile& tile = tiles[t];
    const geom::PlaneBasis& b = tile.projector_to_plane.basis;
    if (tile.width < 2 || tile.height < 2 || tile.width > 16384 || tile.height > 16384)
      return fail(ErrorCode::kInvalidInput, "tile " + std::to_string(t) + ": bad framebuffer size");
    if (std::abs(b.u.norm() - 1) > 1e-6 || std::abs(b.v.norm() - 1) > 1e-6 ||
        std::abs(b.u.dot(b.v)) > 1e-6 || !b.origin.allFinite())
      return fail(ErrorCode::kInvalidInput,
                  "tile " + std::to_string(t) + ": the plane basis is not orthonormal");
    // Same plane, either side: the bases' planes must agree to 1e-6 of normal, 1 mm.
    if (b.normal().cross(plane.n).norm() > 1e-6 || std::abs(plane.signedDistance(b.origin)) > 1e-3)
      return fail(ErrorCode::kInvalidInput,
                  "tile " + std::to_string(t) + " is on another plane than the first");
    geom::PlaneBasis same_side = out.basis;
    auto change = geom::changeOfBasis(b, same_side);
    if (!change) return tl::unexpected(change.error());
    Mat3 to_wall = *change * tile.projector_to_plane.H;
    if (!to_wall.allFinite())
      return fail(ErrorCode::kInvalidInput,
                  "tile " + std::to_string(t) + ": collineation not finite");
    const Vec2 centre(0.5 * (tile.width - 1), 0.5 * (tile.height - 1));
    if ((to_wall * centre.homogeneous()).z() < 0) to_wall = -to_wall;
    const Eigen::FullPivLU<Mat3> lu(to_wall);
    if (!lu.isInvertible())
      return fail(ErrorCode::kInvalidInput,
                  "tile " + std::to_string(t) + ": collineation singular");
    std::array<Vec2, 4> quad;
    const std::array<Vec2, 4> corners = {Vec2(-0.5, -0.5), Vec2(tile.width - 0.5, -0.5),
                                         Vec2(tile.width - 0.5, tile.height - 0.5),
                                         Vec2(-0.5, tile.height - 0.5)};
    for (int k = 0; k < 4; ++k) {
      const Vec3 w = to_wall * corners[k].homogeneous();
      if (!(w.z() > 1e-6 * w.norm()))
        return fail(ErrorCode::kDegenerate,
                    "tile " + std::to_string(t) + ": a framebuffer corner does not reach the wall");
      quad[k] = w.head<2>() / w.z();
      lo = lo.cwiseMin(quad[k]);
      hi = hi.cwiseMax(quad[k]);
    }
    out.footprints.push_back(quad);
    out.plane_to_framebuffer.push_back(lu.inverse());
  }
  const double aspect = double(content_width) / content_height;
  const auto in_union = [&](const Vec2& p) {
    for (const auto& q : out.footprints) {
      if (insideQuad(q, p)) return true;
    }
    return false;
  };
  std::optional<keystone::AxisRect> given = options.rect;
  if (options.world_rect) {
    const WorldRect& w = *options.world_rect;
    if (options.rect)
      return fail(ErrorCode::kInvalidInput, "a display rectangle given twice (rect, world_rect)");
    if (!w.centre.allFinite() || !std::isfinite(w.width) || !std::isfinite(w.height))
      return fail(ErrorCode::kInvalidInput, "the given display rectangle is not finite");
    if (std::abs(plane.signedDistance(w.centre)) > 0.01)
      return fail(ErrorCode::kInvalidInput,
                  "the given display centre is " +
                      std::to_string(std::abs(plane.signedDistance(w.centre))) +
                      " m off the wall plane (at most 0.01)");
    given = keystone::AxisRect{out.basis.toPlane(w.centre), 0.5 * w.width, 0.5 * w.height};
  }
  if (given) {
    const keystone::AxisRect& r = *given;
    if (!r.centre.allFinite() || !(r.half_width > 0) || !(r.half_height > 0))
      return fail(ErrorCode::kInvalidInput, "the given display rectangle is empty");
    // Inside the union: every point of a fine lattice over it is covered.
    const int n = 64;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        const Vec2 p =
            r.centre + Vec2((2.0 * j / n - 1) * r.half_width, (2.0 * i / n - 1) * r.half_height);
        bool in = false;
        for (const auto& q : out.footprints) in = in || insideQuad(q, p);
        if (!in)
          return fail(ErrorCode::kInvalidInput,
                      "the given display rectangle reaches outside the projectors' images");
      }
    }
    out.rect = r;
    out.cell_m = 0;
    out.union_area_m2 = coveredArea(lo, hi, options.raster_cells, in_union);
  } else {
    auto largest = largestRectInRegion(lo, hi, aspect, options.raster_cells, in_union);
    if (!largest) {
      return fail(ErrorCode::kNotFound, "no display rectangle fits the projectors' images");
    }
    out.rect = largest->rect;
    out.cell_m = largest->cell;
    out.union_area_m2 = largest->region_area;
  }
  // A given rectangle is shrunk about its centre to exactly the content's aspect.
  out.rect.half_width = std::min(out.rect.half_width, aspect * out.rect.half_height);
  out.rect.half_height = out.rect.half_width / aspect;
  const Mat3 c2w = contentToWall(out.rect, content_width, content_height);
  for (const Mat3& p2f : out.plane_to_framebuffer) {
    Mat3 H = p2f * c2w;
    out.content_to_framebuffer.push_back(H / H(2, 2));
  }
  return out;
}

}  // namespace procam::blend
