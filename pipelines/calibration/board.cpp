#include "calibration/board.hpp"

#include <cstdio>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#ifdef PROCAM_HAVE_APRILTAG
#include "structured_light/apriltag_grid.hpp"
#endif

namespace procam::calib {
namespace {

cv::Mat grey8(const cv::Mat& image) {
  cv::Mat g;
  if (image.channels() == 3)
    cv::cvtColor(image, g, cv::COLOR_BGR2GRAY);
  else
    g = image;
  if (g.depth() == CV_16U) g.convertTo(g, CV_8U, 1.0 / 257.0);
  return g;
}

cv::Ptr<cv::aruco::CharucoBoard> charucoBoard(const BoardSpec& s) {
  auto dict = cv::aruco::getPredefinedDictionary(s.dictionary);
  return cv::aruco::CharucoBoard::create(s.cols, s.rows, static_cast<float>(s.square_m),
                                         static_cast<float>(s.marker_m), dict);
}

#ifdef PROCAM_HAVE_APRILTAG
// The board in tag modules (a tag36h11 is 8 modules across its black border); one
// module per grid pixel, so corners + 0.5 are module edges.
Result<sl::TagGrid> aprilBoard(const BoardSpec& s, double& metres_per_module) {
  metres_per_module = s.square_m / 8.0;
  const double gap = s.gap_m > 0 ? s.gap_m : 0.25 * s.square_m;
  const int gap_modules = static_cast<int>(std::lround(gap / metres_per_module)) - 2;
  if (gap_modules < 0)
    return fail(ErrorCode::kInvalidInput, "aprilgrid: gap must be at least a quarter of the tag");
  const int pitch = 10 + gap_modules;
  return sl::makeTagGrid({.width = (s.cols - 1) * pitch + 10,
                          .height = (s.rows - 1) * pitch + 10,
                          .module_px = 1,
                          .gap_modules = gap_modules});
}
#endif

}  // namespace

Result<BoardSpec> parseBoard(const std::string& text) {
  BoardSpec s;
  char kind[16] = {0};
  double a = 0, b = 0;
  int n = 0;
  const int fields =
      std::sscanf(text.c_str(), "%15[a-z]:%dx%d:%lf%n", kind, &s.cols, &s.rows, &a, &n);
  const std::string k = kind;
  const char* rest = text.c_str() + (fields == 4 ? n : 0);
  if (fields == 4 && *rest == ':' && std::sscanf(rest, ":%lf", &b) == 1) {
  } else if (fields == 4 && *rest != '\0') {
    return fail(ErrorCode::kParse, "board '" + text + "': trailing text");
  }
  if (fields != 4 || s.cols < 2 || s.rows < 2 || !(a > 0))
    return fail(ErrorCode::kParse,
                "board '" + text +
                    "': expected checker:COLSxROWS:SQUARE_M, "
                    "charuco:COLSxROWS:SQUARE_M:MARKER_M or aprilgrid:COLSxROWS:TAG_M[:GAP_M]");
  s.square_m = a;
  if (k == "checker") {
    s.kind = BoardKind::kChecker;
  } else if (k == "charuco") {
    s.kind = BoardKind::kCharuco;
    s.marker_m = b;
    if (!(b > 0 && b < a))
      return fail(ErrorCode::kParse, "charuco: marker must be smaller than the square");
  } else if (k == "aprilgrid") {
    s.kind = BoardKind::kAprilGrid;
    s.gap_m = b;
  } else {
    return fail(ErrorCode::kParse, "board kind '" + k + "' is not checker, charuco or aprilgrid");
  }
  return s;
}

Result<BoardView> detectBoard(const BoardSpec& s, const cv::Mat& image) {
  if (image.empty()) return fail(ErrorCode::kInvalidInput, "empty board image");
  const cv::Mat g = grey8(image);
  BoardView v;
  try {
    switch (s.kind) {
      case BoardKind::kChecker: {
        std::vector<cv::Point2f> corners;
        const cv::Size size(s.cols, s.rows);
        // The sector-based detector first, as a gate: on a board partly out of view
        // the classic one passes its fast check and then searches for 10 s (measured
        // on 800x600 frames; the gate answers in 40-130 ms). The corners stay the
        // classic detector's, refined below.
        if (!cv::findChessboardCornersSB(g, size, corners, cv::CALIB_CB_NORMALIZE_IMAGE))
          return fail(ErrorCode::kNotFound, "checkerboard not found");
        corners.clear();
        if (!cv::findChessboardCorners(g, size, corners,
                                       cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE |
                                           cv::CALIB_CB_FAST_CHECK))
          return fail(ErrorCode::kNotFound, "checkerboard not found");
        cv::cornerSubPix(
            g, corners, cv::Size(5, 5), cv::Size(-1, -1),
            cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
        for (int i = 0; i < static_cast<int>(corners.size()); ++i) {
          v.image.emplace_back(corners[i].x, corners[i].y);
          v.board.emplace_back((i % s.cols) * s.square_m, (i / s.cols) * s.square_m, 0.0);
        }
        break;
      }
      case BoardKind::kCharuco: {
        auto board = charucoBoard(s);
        std::vector<std::vector<cv::Point2f>> marker_corners;
        std::vector<int> ids;
        cv::aruco::detectMarkers(g, board->dictionary, marker_corners, ids);
        if (ids.size() < 4) return fail(ErrorCode::kNotFound, "ChArUco board: too few markers");
        std::vector<cv::Point2f> corners;
        std::vector<int> corner_ids;
        cv::aruco::interpolateCornersCharuco(marker_corners, ids, g, board, corners, corner_ids);
        if (corners.size() < 6) return fail(ErrorCode::kNotFound, "ChArUco board: too few corners");
        for (std::size_t i = 0; i < corners.size(); ++i) {
          const cv::Point3f& p = board->chessboardCorners[static_cast<std::size_t>(corner_ids[i])];
          v.image.emplace_back(corners[i].x, corners[i].y);
          v.board.emplace_back(p.x, p.y, p.z);
        }
        break;
      }
      case BoardKind::kAprilGrid: {
#ifdef PROCAM_HAVE_APRILTAG
        double m = 0;
        auto grid = aprilBoard(s, m);
        if (!grid) return tl::unexpected(grid.error());
        auto found = sl::detectTagGrid(*grid, g);
        if (!found) return tl::unexpected(found.error());
        if (found->size() < 8) return fail(ErrorCode::kNotFound, "AprilTag board: too few tags");
        for (const auto& c : *found) {
          v.image.push_back(c.image);
          v.board.emplace_back((c.pattern.x() + 0.5) * m, (c.pattern.y() + 0.5) * m, 0.0);
        }
        break;
#else
        return fail(ErrorCode::kInvalidInput, "AprilTag boards need libapriltag (not built)");
#endif
      }
    }
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kInvalidInput, std::string("board detection: ") + e.what());
  }
  return v;
}

Result<cv::Size2d> boardExtent(const BoardSpec& s) {
  switch (s.kind) {
    case BoardKind::kChecker:
      return cv::Size2d((s.cols + 3) * s.square_m, (s.rows + 3) * s.square_m);
    case BoardKind::kCharuco:
      return cv::Size2d((s.cols + 2) * s.square_m, (s.rows + 2) * s.square_m);
    case BoardKind::kAprilGrid: {
#ifdef PROCAM_HAVE_APRILTAG
      double m = 0;
      auto grid = aprilBoard(s, m);
      if (!grid) return tl::unexpected(grid.error());
      return cv::Size2d(grid->options.width * m, grid->options.height * m);
#else
      return fail(ErrorCode::kInvalidInput, "AprilTag boards need libapriltag (not built)");
#endif
    }
  }
  return fail(ErrorCode::kInvalidInput, "unknown board kind");
}

Result<cv::Mat> renderBoard(const BoardSpec& s, double px_per_m) {
  if (!(px_per_m > 0)) return fail(ErrorCode::kInvalidInput, "board rendering: bad scale");
  const int sq = static_cast<int>(std::lround(s.square_m * px_per_m));
  if (sq < 4) return fail(ErrorCode::kInvalidInput, "board rendering: squares under 4 pixels");
  cv::Mat out;
  try {
    switch (s.kind) {
      case BoardKind::kChecker: {
        // cols x rows inner corners: (cols + 1) x (rows + 1) squares, plus a margin.
        out = cv::Mat((s.rows + 3) * sq, (s.cols + 3) * sq, CV_8UC1, cv::Scalar(255));
        for (int r = 0; r <= s.rows; ++r)
          for (int c = 0; c <= s.cols; ++c)
            if ((r + c) % 2 == 0) out(cv::Rect((c + 1) * sq, (r + 1) * sq, sq, sq)).setTo(0);
        break;
      }
      case BoardKind::kCharuco: {
        charucoBoard(s)->draw(cv::Size((s.cols + 2) * sq, (s.rows + 2) * sq), out, sq, 1);
        break;
      }
      case BoardKind::kAprilGrid: {
#ifdef PROCAM_HAVE_APRILTAG
        double m = 0;
        auto grid = aprilBoard(s, m);
        if (!grid) return tl::unexpected(grid.error());
        auto modules = sl::renderTagGrid(*grid);
        if (!modules) return tl::unexpected(modules.error());
        const int px = std::max(1, static_cast<int>(std::lround(m * px_per_m)));
        cv::resize(*modules, out, cv::Size(), px, px, cv::INTER_NEAREST);
        break;
#else
        return fail(ErrorCode::kInvalidInput, "AprilTag boards need libapriltag (not built)");
#endif
      }
    }
  } catch (const cv::Exception& e) {
    return fail(ErrorCode::kInvalidInput, std::string("board rendering: ") + e.what());
  }
  return out;
}

}  // namespace procam::calib
