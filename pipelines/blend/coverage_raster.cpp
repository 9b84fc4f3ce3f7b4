#include "blend/coverage_raster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

namespace procam::blend {
namespace {

// Cell (i, j) has its centre at origin + (j + 0.5, i + 0.5) * cell, 1 where the region
// covers it; `sum` is its integral image.
struct Raster {
  Vec2 origin;
  double cell = 0;
  int cols = 0, rows = 0;
  std::vector<int> sum;  // (rows + 1) x (cols + 1)

  int at(int i, int j) const { return sum[static_cast<std::size_t>(i) * (cols + 1) + j]; }
  int covered(int i0, int j0, int h, int w) const {
    return at(i0 + h, j0 + w) - at(i0, j0 + w) - at(i0 + h, j0) + at(i0, j0);
  }
};

Raster rasterize(const Vec2& lo, const Vec2& hi, double cell,
                 const std::function<bool(const Vec2&)>& covered) {
  Raster r;
  r.origin = lo;
  r.cell = cell;
  r.cols = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)));
  r.rows = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)));
  std::vector<unsigned char> in(static_cast<std::size_t>(r.rows) * r.cols, 0);
  cv::parallel_for_(cv::Range(0, r.rows), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      for (int j = 0; j < r.cols; ++j) {
        in[static_cast<std::size_t>(i) * r.cols + j] = covered(lo + Vec2(j + 0.5, i + 0.5) * cell);
      }
    }
  });
  r.sum.assign(static_cast<std::size_t>(r.rows + 1) * (r.cols + 1), 0);
  for (int i = 0; i < r.rows; ++i) {
    int row = 0;
    for (int j = 0; j < r.cols; ++j) {
      row += in[static_cast<std::size_t>(i) * r.cols + j];
      r.sum[static_cast<std::size_t>(i + 1) * (r.cols + 1) + j + 1] = r.at(i, j + 1) + row;
    }
  }
  return r;
}

struct Placement {
  int i = 0, j = 0, h = 0, w = 0;  // rows, columns of cells
};

// The largest fully covered h x w block with w = round(aspect h), closest to `prefer`
// (cell coordinates of the preferred centre) among those of that size.
std::optional<Placement> largestBlock(const Raster& r, double aspect, const Vec2& prefer,
                                      int known_h = 0) {
  auto fits = [&](int h, Placement* best) {
    const int w = std::max(1, static_cast<int>(std::lround(aspect * h)));
    if (h > r.rows || w > r.cols) return false;
    bool any = false;
    double best_d = std::numeric_limits<double>::infinity();
    for (int i = 0; i + h <= r.rows; ++i) {
      for (int j = 0; j + w <= r.cols; ++j) {
        if (r.covered(i, j, h, w) != h * w) continue;
        any = true;
        if (!best) return true;
        const double d = (Vec2(j + 0.5 * w, i + 0.5 * h) - prefer).squaredNorm();
        if (d < best_d) {
          best_d = d;
          *best = {i, j, h, w};
        }
      }
    }
    return any;
  };
  int lo = std::min(known_h, r.rows), hi = r.rows;  // lo fits, hi + 1 does not
  if (lo > 0 && !fits(lo, nullptr)) lo = 0;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (fits(mid, nullptr))
      lo = mid;
    else
      hi = mid - 1;
  }
  if (lo == 0) return std::nullopt;
  Placement p;
  fits(lo, &p);
  return p;
}

keystone::AxisRect toRect(const Raster& r, const Placement& p) {
  keystone::AxisRect rect;
  rect.centre = r.origin + Vec2(p.j + 0.5 * p.w, p.i + 0.5 * p.h) * r.cell;
  rect.half_width = 0.5 * p.w * r.cell;
  rect.half_height = 0.5 * p.h * r.cell;
  return rect;
}

}  // namespace

Result<LargestRect> largestRectInRegion(const Vec2& lo, const Vec2& hi, double aspect, int cells,
                                        const std::function<bool(const Vec2&)>& covered) {
  if (!lo.allFinite() || !hi.allFinite() || !(hi.x() > lo.x()) || !(hi.y() > lo.y()))
    return fail(ErrorCode::kInvalidInput, "the region's bounds are empty or not finite");
  if (!(aspect > 0) || !std::isfinite(aspect))
    return fail(ErrorCode::kInvalidInput, "the rectangle's aspect must be positive");
  if (cells < 16 || cells > 8192)
    return fail(ErrorCode::kInvalidInput, "raster cells outside [16, 8192]");
  LargestRect out;
  const double coarse = (hi - lo).maxCoeff() / cells;
  const Raster whole = rasterize(lo, hi, coarse, covered);
  out.region_area = whole.at(whole.rows, whole.cols) * coarse * coarse;
  const Vec2 centroid = 0.5 * (lo + hi);
  auto block = largestBlock(whole, aspect, (centroid - lo) / coarse);
  if (!block) return fail(ErrorCode::kNotFound, "no rectangle fits the region");
  const keystone::AxisRect rough = toRect(whole, *block);
  // Four times finer around it: the true rectangle is at most one coarse cell larger on
  // every side.
  const double fine = coarse / 4;
  const Vec2 margin = Vec2::Constant(2 * coarse) + Vec2(aspect, 1.0) * 2 * coarse;
  const Vec2 flo = (rough.centre - Vec2(rough.half_width, rough.half_height) - margin).cwiseMax(lo);
  const Vec2 fhi = (rough.centre + Vec2(rough.half_width, rough.half_height) + margin).cwiseMin(hi);
  const Raster local = rasterize(flo, fhi, fine, covered);
  auto fine_block =
      largestBlock(local, aspect, (rough.centre - flo) / fine, std::max(0, 4 * block->h - 4));
  out.rect = fine_block ? toRect(local, *fine_block) : rough;
  out.cell = fine_block ? fine : coarse;
  // Coverage was sampled at cell centres: half a cell in from every side, the rectangle
  // is inside the region; then exactly the aspect, about the chosen centre.
  out.rect.half_width -= 0.5 * out.cell;
  out.rect.half_height -= 0.5 * out.cell;
  out.rect.half_width = std::min(out.rect.half_width, aspect * out.rect.half_height);
  out.rect.half_height = out.rect.half_width / aspect;
  if (!(out.rect.half_width > 0)) return fail(ErrorCode::kNotFound, "no rectangle fits the region");
  return out;
}

double coveredArea(const Vec2& lo, const Vec2& hi, int cells,
                   const std::function<bool(const Vec2&)>& covered) {
  if (!lo.allFinite() || !hi.allFinite() || !(hi.x() > lo.x()) || !(hi.y() > lo.y()) ||
      cells < 16 || cells > 8192)
    return 0;
  const double cell = (hi - lo).maxCoeff() / cells;
  const Raster r = rasterize(lo, hi, cell, covered);
  return r.at(r.rows, r.cols) * cell * cell;
}

}  // namespace procam::blend
