#pragma once
// Fills the unknown cells of a grid outward from the known ones: each pass gives every
// unknown cell with a known 8-neighbour the mean of its known neighbours, until no cell
// changes (cells no known cell connects to stay unknown). Shared by the brightness map
// (nodes the camera did not see) and the luminance match (content cells no light reached).
#include <opencv2/core.hpp>

namespace procam::blend {

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
