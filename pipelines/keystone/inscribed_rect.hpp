#pragma once
// The largest rectangle of a given aspect ratio, with sides parallel to the axes, inside
// a convex polygon (the keystoned image on the wall, [Raskar02] §3.2.5 Fig. 3.8).
//
// For a fixed aspect a the rectangle is (centre c, half height h, half width a*h). It is
// inside the convex polygon iff every edge half-plane n·p <= b holds at its worst corner:
//   n·c + h (a|n_x| + |n_y|) <= b.
// That is a linear program in (c_x, c_y, h); with a handful of edges it is solved
// exactly by enumerating the vertices (three active constraints). Coordinates: x right,
// y UP (wall coordinates), so "top" means largest y.
#include <optional>
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::keystone {

struct AxisRect {
  Vec2 centre = Vec2::Zero();
  double half_width = 0, half_height = 0;
  double area() const { return 4 * half_width * half_height; }
};

enum class Anchor {
  kCentre,        // centre of the set of largest rectangles
  kTop,           // highest position (then closest to the centred one horizontally)
  kKeepPrevious,  // feasible position closest to InscribeOptions::previous_centre
};

struct InscribeOptions {
  Anchor anchor = Anchor::kCentre;
  // Size relative to the largest rectangle, in (0, 1]. Below 1 the rectangle can move,
  // and the anchor decides where it goes.
  double zoom = 1.0;
  std::optional<Vec2> previous_centre;  // used by kKeepPrevious (centred if absent)
};

// `polygon`: >= 3 vertices of a convex polygon in either winding. aspect = width/height.
// kInvalidInput for NaN/Inf, aspect <= 0, zoom outside (0, 1]; kDegenerate for a
// non-convex or zero-area polygon.
Result<AxisRect> largestInscribedRect(std::span<const Vec2> polygon, double aspect,
                                      const InscribeOptions& options = {});

}  // namespace procam::keystone
