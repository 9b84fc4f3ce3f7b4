// BoardViewSet: which board views a camera calibration keeps, and how much of the
// image they cover, on synthetic views whose answer is known by construction.
#include <gtest/gtest.h>

#include "calibration/board_view_set.hpp"

namespace procam::calib {
namespace {

// A 9x6 grid of board points (5 cm) seen as an axis-aligned grid of `pitch` pixels
// starting at (x0, y0).
BoardView gridView(double x0, double y0, double pitch) {
  BoardView v;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 9; ++c) {
      v.board.emplace_back(0.05 * c, 0.05 * r, 0.0);
      v.image.emplace_back(x0 + pitch * c, y0 + pitch * r);
    }
  }
  return v;
}

TEST(BoardViewSet, KeepsNewViewsAndRejectsRepeats) {
  BoardViewSet set(800, 600, 20.0);
  EXPECT_EQ(set.offer(gridView(100, 100, 30)), ViewVerdict::kAccepted);
  // 10 px away on average: a repeat of the first.
  EXPECT_EQ(set.offer(gridView(110, 100, 30)), ViewVerdict::kRepeated);
  // 25 px away: new.
  EXPECT_EQ(set.offer(gridView(125, 100, 30)), ViewVerdict::kAccepted);
  // A larger board image (the board nearer) shifts the far corners by 8 x 10 px.
  EXPECT_EQ(set.offer(gridView(100, 100, 40)), ViewVerdict::kAccepted);
  EXPECT_EQ(set.views().size(), 3u);

  BoardView few = gridView(500, 400, 20);
  few.image.resize(5);
  few.board.resize(5);
  EXPECT_EQ(set.offer(few), ViewVerdict::kTooFewPoints);
  EXPECT_EQ(set.offer(gridView(700, 100, 20)), ViewVerdict::kOutside);  // x up to 860
  BoardView nan = gridView(300, 300, 20);
  nan.image[7].x() = std::nan("");
  EXPECT_EQ(set.offer(nan), ViewVerdict::kOutside);
  EXPECT_EQ(set.views().size(), 3u);
}

TEST(BoardViewSet, PartialViewsShareOnlyTheirCommonPoints) {
  BoardViewSet set(800, 600, 20.0);
  BoardView left = gridView(100, 100, 30);
  ASSERT_EQ(set.offer(left), ViewVerdict::kAccepted);
  // The same pose with the right half of the board hidden (a partial detection):
  // the points it shares have not moved, so it repeats the kept view.
  BoardView half;
  for (std::size_t i = 0; i < left.board.size(); ++i) {
    if (left.board[i].x() < 0.2) {
      half.board.push_back(left.board[i]);
      half.image.push_back(left.image[i]);
    }
  }
  EXPECT_EQ(set.offer(half), ViewVerdict::kRepeated);
}

TEST(BoardViewSet, CoverageIsTheShareOfCellsInsideTheViews) {
  // 4 x 3 cells of 200 x 200 px; a view spanning x 0..399, y 0..399 (hull corners on
  // those pixels) holds the centres of cells (0,0), (1,0), (0,1), (1,1).
  BoardViewSet set(800, 600, 20.0, 4, 3);
  EXPECT_DOUBLE_EQ(set.coverage(), 0.0);
  ASSERT_EQ(set.offer(gridView(0, 0, 399.0 / 8 * 1.0)), ViewVerdict::kAccepted);
  // gridView spans 8 pitches across and 5 down: x 0..399, y 0..249.4: cells (0,0), (1,0).
  EXPECT_DOUBLE_EQ(set.coverage(), 2.0 / 12.0);
  ASSERT_EQ(set.offer(gridView(400, 300, 49.0)), ViewVerdict::kAccepted);  // x 400..792, y 300..545
  // Adds the centres (499.5, 499.5) and (699.5, 499.5): cells (2,2) and (3,2).
  EXPECT_DOUBLE_EQ(set.coverage(), 4.0 / 12.0);
}

}  // namespace
}  // namespace procam::calib
