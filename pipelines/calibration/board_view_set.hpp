#pragma once
// The board views a camera calibration keeps while an installer moves a board in
// front of the camera ([Zhang99]: intrinsics need the board at several
// orientations, and the image covered, for the distortion to be observed
// everywhere): a view is kept unless it repeats one already kept, and the set
// reports how much of the image its views cover.
#include <map>
#include <span>
#include <utility>
#include <vector>

#include "calibration/board.hpp"

namespace procam::calib {

enum class ViewVerdict {
  kAccepted,
  kTooFewPoints,  // fewer than 6 board points: no homography worth the name
  kOutside,       // a point outside the image (a detection that cannot be)
  kRepeated,      // within the shift threshold of a kept view: adds nothing
};
const char* toString(ViewVerdict verdict);

class BoardViewSet {
 public:
  // `min_shift_px`: the mean image distance between the points two views share below
  // which the second repeats the first. `cells_x` x `cells_y`: the coverage raster.
  BoardViewSet(int width, int height, double min_shift_px, int cells_x = 16, int cells_y = 12);

  ViewVerdict offer(const BoardView& view);

  std::span<const BoardView> views() const { return views_; }
  // The fraction of raster cells whose centre lies inside the convex hull of a kept
  // view's image points, in [0, 1].
  double coverage() const;

 private:
  int width_, height_;
  double min_shift_px_;
  int cells_x_, cells_y_;
  std::vector<BoardView> views_;
  // Each kept view's image points by board point, for the repeat test.
  std::vector<std::map<std::pair<long long, long long>, Vec2>> keyed_;
  std::vector<unsigned char> covered_;  // cells_y_ x cells_x_
};

}  // namespace procam::calib
