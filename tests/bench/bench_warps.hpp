#pragma once
// Warps the render benches share, so that their frame times are of the same work.
#include <cmath>
#include <opencv2/core.hpp>

#include "render/render_setup.hpp"

namespace procam::bench {

// A smooth lookup warp over the whole frame: nodes every 16 px, displaced by up to ~20 px.
inline render::WarpGrid lookupGrid(cv::Size size) {
  render::WarpGrid g;
  g.step = Vec2(16, 16);
  g.cols = size.width / 16 + 2;
  g.rows = size.height / 16 + 2;
  for (int j = 0; j < g.rows; ++j) {
    for (int i = 0; i < g.cols; ++i) {
      const Vec2 n = g.node(i, j);
      g.source.push_back(n + Vec2(14 * std::sin(n.y() / 230.0) + 6 * std::cos(n.x() / 310.0),
                                  11 * std::cos(n.x() / 270.0) - 5 * std::sin(n.y() / 190.0)));
    }
  }
  return g;
}

}  // namespace procam::bench
