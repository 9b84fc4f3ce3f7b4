#pragma once
// Scan conversion of one triangle over pixel centres (ARCHITECTURE.md convention), with a
// top-left rule so that pixels on an edge shared by two triangles are drawn once.
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/types.hpp"

namespace procam::render {

// Calls fn(x, y, b0, b1, b2) for every pixel centre (x, y) with 0 <= x < width and
// row_begin <= y < row_end inside the triangle p0 p1 p2; b are the screen-space
// barycentric coordinates. Row ranges let callers split one image across threads.
template <class Fn>
void rasterizeTriangleRows(const Vec2& p0, const Vec2& p1, const Vec2& p2, int width, int row_begin,
                           int row_end, Fn&& fn) {
  auto edge = [](const Vec2& a, const Vec2& b, double x, double y) {
    return (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
  };
  const double area = edge(p0, p1, p2.x(), p2.y());
  if (!(std::abs(area) > 0) || !std::isfinite(area)) return;
  // Orient so that inside means all edge functions positive.
  const Vec2& a = p0;
  const Vec2& b = area > 0 ? p1 : p2;
  const Vec2& c = area > 0 ? p2 : p1;
  const double inv_area = 1.0 / std::abs(area);
  // An edge owns its boundary pixels when it is a "top" (horizontal, interior below in
  // y-down images) or "left" edge.
  auto owns = [](const Vec2& from, const Vec2& to) {
    const double dy = to.y() - from.y(), dx = to.x() - from.x();
    return dy < 0 || (dy == 0 && dx > 0);
  };
  const bool own_bc = owns(b, c), own_ca = owns(c, a), own_ab = owns(a, b);
  const double min_x = std::min({a.x(), b.x(), c.x()}), max_x = std::max({a.x(), b.x(), c.x()});
  const double min_y = std::min({a.y(), b.y(), c.y()}), max_y = std::max({a.y(), b.y(), c.y()});
  const int x0 = std::max(0, static_cast<int>(std::ceil(min_x)));
  const int x1 = std::min(width - 1, static_cast<int>(std::floor(max_x)));
  const int y0 = std::max(row_begin, static_cast<int>(std::ceil(min_y)));
  const int y1 = std::min(row_end - 1, static_cast<int>(std::floor(max_y)));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double ea = edge(b, c, x, y), eb = edge(c, a, x, y), ec = edge(a, b, x, y);
      if (ea < 0 || eb < 0 || ec < 0) continue;
      if ((ea == 0 && !own_bc) || (eb == 0 && !own_ca) || (ec == 0 && !own_ab)) continue;
      const double ba = ea * inv_area, bb = eb * inv_area, bc = ec * inv_area;
      // Report in the caller's vertex order.
      if (area > 0) {
        fn(x, y, ba, bb, bc);
      } else {
        fn(x, y, ba, bc, bb);
      }
    }
  }
}

// The whole width x height image.
template <class Fn>
void rasterizeTriangle(const Vec2& p0, const Vec2& p1, const Vec2& p2, int width, int height,
                       Fn&& fn) {
  rasterizeTriangleRows(p0, p1, p2, width, 0, height, std::forward<Fn>(fn));
}

}  // namespace procam::render
