#include "demo/checkerboard.hpp"

namespace procam::demo {

Checkerboard makeCheckerboard(int width, int height, int square) {
  const int cols = width / square - 2;   // squares across, leaving a margin
  const int rows = height / square - 2;
  const int x0 = (width - cols * square) / 2;
  const int y0 = (height - rows * square) / 2;
  Checkerboard board;
  board.image = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if ((r + c) % 2 == 0) {
        board.image(cv::Rect(x0 + c * square, y0 + r * square, square, square)).setTo(0);
      }
    }
  }
  board.inner = cv::Size(cols - 1, rows - 1);
  // A square edge lies between two pixel centres: x = first pixel - 0.5.
  for (int r = 1; r < rows; ++r) {
    for (int c = 1; c < cols; ++c) {
      board.corners.emplace_back(x0 + c * square - 0.5, y0 + r * square - 0.5);
    }
  }
  return board;
}

}  // namespace procam::demo
