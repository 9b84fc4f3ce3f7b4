#pragma once
// One display from several projectors on a planar wall ([Raskar02] §4.2.4): each
// projector's collineation with the wall plane (calibration route (b′)) gives its image
// on the wall; the content is shown in the largest upright rectangle of its aspect
// inside the union of those images (the single-projector keystone rectangle of §3.2.5,
// generalised), and each projector gets the homography content -> its framebuffer
// through that rectangle. The union of convex footprints is not convex, so the
// rectangle is searched on a raster of the wall (coverage tested with an integral
// image), coarse over the whole union and then four times finer around the best
// coarse rectangle.
#include <array>
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/plane_homography.hpp"
#include "keystone/inscribed_rect.hpp"

namespace procam::blend {

struct DisplayTile {
  geom::PlaneHomography projector_to_plane;  // framebuffer pixels -> plane basis
  int width = 0, height = 0;                 // framebuffer size
};

// An upright display rectangle in world coordinates: its centre (a point on the wall,
// metres; within 1 cm of the plane) and its width and height on the wall (metres).
struct WorldRect {
  Vec3 centre = Vec3::Zero();
  double width = 0, height = 0;
};

struct TiledDisplayOptions {
  int raster_cells = 512;  // cells along the union's longer side, coarse pass
  // A display rectangle given by the user (wall metres in the display basis, x right,
  // y up) instead of the largest one; it must lie inside the union.
  std::optional<keystone::AxisRect> rect;
  // The same given in world coordinates (the basis is only known once solved); not
  // with `rect`. Shrunk about its centre to the content's aspect, as `rect` is.
  std::optional<WorldRect> world_rect;
};

struct TiledDisplay {
  geom::PlaneBasis basis;   // upright basis of the wall (origin: the first tile's)
  keystone::AxisRect rect;  // the display rectangle, metres in `basis` (x right, y up)
  std::vector<std::array<Vec2, 4>> footprints;  // per tile, framebuffer corners on the wall
  std::vector<Mat3> plane_to_framebuffer;       // per tile: (x, y, 1) in `basis` -> pixels
  std::vector<Mat3> content_to_framebuffer;     // per tile: H, content pixels -> pixels
  double union_area_m2 = 0;                     // of the footprints, raster estimate
  double cell_m = 0;                            // the fine raster's cell: the rect's accuracy
};

// kInvalidInput for no tiles, bad sizes, a non-orthonormal basis, a singular
// collineation, tiles on different planes (more than 1 mm or 1e-6 of normal apart) or a
// given rectangle outside the union (or a world one off the wall plane); kDegenerate for a
// horizontal wall or a framebuffer corner beyond the wall's horizon; kNotFound when no rectangle of
// one fine cell fits.
Result<TiledDisplay> solveTiledDisplay(std::span<const DisplayTile> tiles, int content_width,
                                       int content_height, const TiledDisplayOptions& options = {});

// Content pixels (outer edges -0.5 ... size - 0.5) -> wall metres of `rect` (y up).
Mat3 contentToWall(const keystone::AxisRect& rect, int content_width, int content_height);

}  // namespace procam::blend
