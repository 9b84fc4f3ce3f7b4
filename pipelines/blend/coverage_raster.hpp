#pragma once
// The largest upright rectangle of a given aspect inside a region of a plane that is
// not convex (the union of several projectors' images): the region is sampled on a
// raster, coverage of every block tested with an integral image, coarse over the whole
// region and then four times finer around the best coarse rectangle. Shared by the
// planar tiled display (the wall plane) and the curved one (the viewer's image plane).
#include <functional>
#include <optional>

#include "core/error.hpp"
#include "core/types.hpp"
#include "keystone/inscribed_rect.hpp"

namespace procam::blend {

struct LargestRect {
  keystone::AxisRect rect;  // inside the region at every fine cell centre, exact aspect
  double cell = 0;          // the fine raster's cell: the rectangle's accuracy
  double region_area = 0;   // of the region, coarse raster estimate
};

// `covered(p)`: whether the point p (x right, y up) is inside the region; called from
// several threads at once. The region lies in [lo, hi]; `cells` along its longer side
// in the coarse pass, in [16, 8192]. kInvalidInput for bad bounds, aspect or cells;
// kNotFound when no rectangle of one fine cell fits.
Result<LargestRect> largestRectInRegion(const Vec2& lo, const Vec2& hi, double aspect, int cells,
                                        const std::function<bool(const Vec2&)>& covered);

// The region's area estimated on the coarse raster largestRectInRegion uses (0 for bad
// bounds or cells).
double coveredArea(const Vec2& lo, const Vec2& hi, int cells,
                   const std::function<bool(const Vec2&)>& covered);

}  // namespace procam::blend
