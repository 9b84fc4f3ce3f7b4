#include "calibration/board_view_set.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

namespace procam::calib {

namespace {

constexpr std::size_t kMinPoints = 6;

// A board point as a key: micrometres, exact for the boards' metric grid.
std::pair<long long, long long> key(const Vec3& p) {
  return {std::llround(p.x() * 1e6), std::llround(p.y() * 1e6)};
}

// The mean distance between the image points of the board points `a` and `b` share;
// infinity when they share fewer than kMinPoints (partial boards: ChArUco, AprilGrid).
double meanShift(const BoardView& a, const std::map<std::pair<long long, long long>, Vec2>& b) {
  double sum = 0;
  std::size_t shared = 0;
  for (std::size_t i = 0; i < a.board.size(); ++i) {
    auto it = b.find(key(a.board[i]));
    if (it == b.end()) continue;
    sum += (a.image[i] - it->second).norm();
    ++shared;
  }
  return shared < kMinPoints ? INFINITY : sum / double(shared);
}

}  // namespace

const char* toString(ViewVerdict verdict) {
  switch (verdict) {
    case ViewVerdict::kAccepted:
      return "accepted";
    case ViewVerdict::kTooFewPoints:
      return "too few points";
    case ViewVerdict::kOutside:
      return "points outside the image";
    case ViewVerdict::kRepeated:
      return "repeats a kept view";
  }
  return "unknown";
}

BoardViewSet::BoardViewSet(int width, int height, double min_shift_px, int cells_x, int cells_y)
    : width_(width),
      height_(height),
      min_shift_px_(min_shift_px),
      cells_x_(std::max(1, cells_x)),
      cells_y_(std::max(1, cells_y)),
      covered_(std::size_t(cells_x_) * std::size_t(cells_y_), 0) {}

ViewVerdict BoardViewSet::offer(const BoardView& view) {
  if (view.image.size() < kMinPoints || view.image.size() != view.board.size()) {
    return ViewVerdict::kTooFewPoints;
  }
  for (const auto& p : view.image) {
    // Pixel-centre convention: the image spans [-0.5, size - 0.5].
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || p.x() < -0.5 || p.y() < -0.5 ||
        p.x() > width_ - 0.5 || p.y() > height_ - 0.5) {
      return ViewVerdict::kOutside;
    }
  }
  for (const auto& kept : keyed_) {
    if (meanShift(view, kept) < min_shift_px_) return ViewVerdict::kRepeated;
  }
  views_.push_back(view);
  auto& keyed = keyed_.emplace_back();
  for (std::size_t i = 0; i < view.board.size(); ++i) keyed[key(view.board[i])] = view.image[i];
  std::vector<cv::Point2f> points, hull;
  for (const auto& p : view.image) points.emplace_back(float(p.x()), float(p.y()));
  cv::convexHull(points, hull);
  for (int cy = 0; cy < cells_y_; ++cy) {
    for (int cx = 0; cx < cells_x_; ++cx) {
      const cv::Point2f centre(float((cx + 0.5) * width_ / cells_x_ - 0.5),
                               float((cy + 0.5) * height_ / cells_y_ - 0.5));
      if (cv::pointPolygonTest(hull, centre, false) >= 0) {
        covered_[std::size_t(cy) * std::size_t(cells_x_) + std::size_t(cx)] = 1;
      }
    }
  }
  return ViewVerdict::kAccepted;
}

double BoardViewSet::coverage() const {
  const auto n = std::count(covered_.begin(), covered_.end(), 1);
  return double(n) / double(covered_.size());
}

}  // namespace procam::calib
