#pragma once
// Calibration boards and their detection: checkerboard, ChArUco and an AprilTag
// (tag36h11) grid. Each detection yields image points and the matching board
// points (metres, board plane z = 0) for cv::calibrateCamera ([Raskar02] §7.3, [Zhang99]).
#include <opencv2/core.hpp>
#include <string>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::calib {

enum class BoardKind { kChecker, kCharuco, kAprilGrid };

struct BoardSpec {
  BoardKind kind = BoardKind::kChecker;
  int cols = 0, rows = 0;  // checker: inner corners; ChArUco: squares; AprilGrid: tags
  double square_m = 0;     // checker/ChArUco square side; AprilGrid: tag side (black border)
  double marker_m = 0;     // ChArUco marker side
  double gap_m = 0;        // AprilGrid: space between tags (default: a quarter of the tag)
  int dictionary = 0;      // ChArUco: cv::aruco predefined dictionary id (0: DICT_4X4_50)
};

// "checker:COLSxROWS:SQUARE_M", "charuco:COLSxROWS:SQUARE_M:MARKER_M",
// "aprilgrid:COLSxROWS:TAG_M[:GAP_M]"; kParse with the expected form on error.
Result<BoardSpec> parseBoard(const std::string& text);

struct BoardView {
  Points2 image;  // pixel-centre convention
  Points3 board;  // metres, z = 0
};

// kNotFound when the board is not (fully enough) visible; 8-bit grey or BGR input.
Result<BoardView> detectBoard(const BoardSpec& spec, const cv::Mat& image);

// The physical size (metres, width x height) of what renderBoard draws, margins
// included, whatever its pixel scale: a print of that image at this size has the
// board's true dimensions.
Result<cv::Size2d> boardExtent(const BoardSpec& spec);

// The board as an 8-bit image with `px_per_m` pixels per metre and a white margin of
// one square: for printing, and for rendering views in tests.
Result<cv::Mat> renderBoard(const BoardSpec& spec, double px_per_m);

}  // namespace procam::calib
