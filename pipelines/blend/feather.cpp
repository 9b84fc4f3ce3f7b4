#include "blend/feather.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace procam::blend {

double insideDistance(const std::array<Vec2, 4>& q, const Vec2& p) {
  // Orientation of the quad, so that inside is on the same side of every edge.
  double area2 = 0;
  for (int i = 0; i < 4; ++i)
    area2 += q[i].x() * q[(i + 1) % 4].y() - q[(i + 1) % 4].x() * q[i].y();
  const double orient = area2 >= 0 ? 1.0 : -1.0;
  double d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    const Vec2 a = q[i], e = q[(i + 1) % 4] - a;
    const double len = e.norm();
    if (!(len > 0)) continue;
    // Signed distance to the edge's line, positive inside.
    const double s = orient * (e.x() * (p.y() - a.y()) - e.y() * (p.x() - a.x())) / len;
    d = std::min(d, s);
  }
  return std::isfinite(d) ? std::max(d, 0.0) : 0.0;
}

namespace {

// Bilinear sample of a CV_32FC1 image at (x, y), clamped to its border.
float sample(const cv::Mat& m, double x, double y) {
  x = std::clamp(x, 0.0, m.cols - 1.0);
  y = std::clamp(y, 0.0, m.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), m.cols - 2 < 0 ? 0 : m.cols - 2);
  const int y0 = std::min(static_cast<int>(y), m.rows - 2 < 0 ? 0 : m.rows - 2);
  const int x1 = std::min(x0 + 1, m.cols - 1), y1 = std::min(y0 + 1, m.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const double top = (1 - fx) * m.at<float>(y0, x0) + fx * m.at<float>(y0, x1);
  const double bottom = (1 - fx) * m.at<float>(y1, x0) + fx * m.at<float>(y1, x1);
  return static_cast<float>((1 - fy) * top + fy * bottom);
}

}  // namespace

Result<std::vector<cv::Mat>> featherWeights(std::span<const FeatherTile> tiles, int raster_cells) {
  if (tiles.empty()) return fail(ErrorCode::kInvalidInput, "no tiles to feather");
  if (raster_cells < 64 || raster_cells > 8192)
    return fail(ErrorCode::kInvalidInput, "feathering: raster_cells outside [64, 8192]");
  std::vector<Mat3> framebuffer_to_plane;
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const FeatherTile& t : tiles) {
    if (t.width < 1 || t.height < 1 || t.width > 16384 || t.height > 16384)
      return fail(ErrorCode::kInvalidInput, "feathering: bad framebuffer size");
    const Eigen::FullPivLU<Mat3> lu(t.plane_to_framebuffer);
    if (!t.plane_to_framebuffer.allFinite() || !lu.isInvertible())
      return fail(ErrorCode::kInvalidInput, "feathering: singular plane mapping");
    framebuffer_to_plane.push_back(lu.inverse());
    for (const Vec2& c : t.footprint) {
      if (!c.allFinite()) return fail(ErrorCode::kInvalidInput, "feathering: footprint not finite");
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
  }
  const double extent = (hi - lo).maxCoeff();
  if (!(extent > 0)) return fail(ErrorCode::kInvalidInput, "feathering: empty footprints");
  // The wall raster, one cell of margin all round so that the union's outside exists.
  const double cell = extent / raster_cells;
  const int cols = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 2;
  const int rows = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 2;
  auto toRaster = [&](const Vec2& p) {
    return Vec2((p.x() - lo.x()) / cell + 0.5, (p.y() - lo.y()) / cell + 0.5);
  };
  constexpr int kShift = 8;  // sub-cell precision of the polygon fill
  std::vector<cv::Mat> masks;
  cv::Mat none(rows, cols, CV_8UC1, cv::Scalar(0));
  for (const FeatherTile& t : tiles) {
    cv::Mat m(rows, cols, CV_8UC1, cv::Scalar(0));
    std::array<cv::Point, 4> poly;
    for (int k = 0; k < 4; ++k) {
      const Vec2 r = toRaster(t.footprint[k]) * (1 << kShift);
      poly[k] =
          cv::Point(static_cast<int>(std::lround(r.x())), static_cast<int>(std::lround(r.y())));
    }
    cv::fillConvexPoly(m, poly.data(), 4, cv::Scalar(255), cv::LINE_8, kShift);
    none |= m;
    masks.push_back(m);
  }
  cv::bitwise_not(none, none);  // outside every image
  // d_i: the distance to the nearest wall point that another image lights and image i
  // does not (cells); the union's outside counts as lit by every image.
  std::vector<cv::Mat> dist(tiles.size());
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    cv::Mat keep = masks[i] | none;
    cv::distanceTransform(keep, dist[i], cv::DIST_L2, cv::DIST_MASK_PRECISE);
  }
  std::vector<cv::Mat> out;
  for (std::size_t m = 0; m < tiles.size(); ++m) {
    const FeatherTile& tile = tiles[m];
    cv::Mat w(tile.height, tile.width, CV_32FC1);
    cv::parallel_for_(cv::Range(0, tile.height), [&](const cv::Range& range) {
      for (int y = range.start; y < range.end; ++y) {
        float* row = w.ptr<float>(y);
        for (int x = 0; x < tile.width; ++x) {
          const Vec3 h = framebuffer_to_plane[m] * Vec3(x, y, 1);
          if (!(std::abs(h.z()) > 1e-12)) {
            row[x] = 0.f;
            continue;
          }
          const Vec2 p = h.head<2>() / h.z();
          const Vec2 r = toRaster(p);  // the fill's coordinates: cell centres at integers
          double own = 0, sum = 0;
          for (std::size_t i = 0; i < tiles.size(); ++i) {
            if (i != m && insideDistance(tiles[i].footprint, p) <= 0) continue;
            const double d = sample(dist[i], r.x(), r.y());
            if (i == m) own = d;
            sum += d;
          }
          row[x] = sum > 0 ? static_cast<float>(own / sum) : 1.f;
        }
      }
    });
    out.push_back(w);
  }
  return out;
}

cv::Mat alphaMask(const cv::Mat& weights) {
  cv::Mat a;
  weights.convertTo(a, CV_8UC1, 255.0);  // saturating, rounded
  return a;
}

}  // namespace procam::blend
