#pragma once
// Regular grids of values (a brightness map's nodes, the luminance match's content
// raster): filling the unknown cells from the known ones, and bilinear sampling between
// nodes. Shared by brightness_map.cpp and luminance_match.cpp.
#include <algorithm>
#include <opencv2/core.hpp>

namespace procam::blend {

// Bilinear between nodes at grid coordinates (fx, fy) (node (i, j) at (i, j)), clamped
// to the grid's extent.
template <typename T>
double sampleNodes(const cv::Mat_<T>& grid, double fx, double fy) {
  fx = std::clamp(fx, 0.0, grid.cols - 1.0);
  fy = std::clamp(fy, 0.0, grid.rows - 1.0);
  const int i = std::min(static_cast<int>(fx), std::max(grid.cols - 2, 0));
  const int j = std::min(static_cast<int>(fy), std::max(grid.rows - 2, 0));
  const int i1 = std::min(i + 1, grid.cols - 1), j1 = std::min(j + 1, grid.rows - 1);
  const double tx = fx - i, ty = fy - j;
  return (1 - ty) * ((1 - tx) * grid(j, i) + tx * grid(j, i1)) +
         ty * ((1 - tx) * grid(j1, i) + tx * grid(j1, i1));
}

// Fills the unknown cells of a grid outward from the known ones: each pass gives every
// unknown cell with a known 8-neighbour the mean of its known neighbours, until no cell
// changes (cells no known cell connects to stay unknown).
template <typename T>
void fillFromKnownNeighbours(cv::Mat_<T>& value, cv::Mat_<uchar>& known) {
  for (bool grew = true; grew;) {
    grew = false;
    const cv::Mat_<uchar> before = known.clone();
    for (int j = 0; j < value.rows; ++j) {
      for (int i = 0; i < value.cols; ++i) {
        if (before(j, i)) continue;
        double sum = 0;
        int n = 0;
        for (int y = std::max(j - 1, 0); y <= std::min(j + 1, value.rows - 1); ++y) {
          for (int x = std::max(i - 1, 0); x <= std::min(i + 1, value.cols - 1); ++x) {
            if (!before(y, x)) continue;
            sum += value(y, x);
            ++n;
          }
        }
        if (n == 0) continue;
        value(j, i) = static_cast<T>(sum / n);
        known(j, i) = 1;
        grew = true;
      }
    }
  }
}

}  // namespace procam::blend
