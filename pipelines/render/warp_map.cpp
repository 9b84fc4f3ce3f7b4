#include "render/warp_map.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace procam::render {
namespace {

bool finite(const Mat3& m) {
  return m.allFinite();
}

cv::Vec2f outside() {
  return cv::Vec2f(kOutside, kOutside);
}

bool isOutside(const cv::Vec2f& v) {
  return v[0] == kOutside;
}

}  // namespace

WarpMap identityMap(cv::Size size) {
  WarpMap map{cv::Mat(size, CV_32FC2)};
  for (int y = 0; y < size.height; ++y) {
    auto* row = map.xy.ptr<cv::Vec2f>(y);
    for (int x = 0; x < size.width; ++x) row[x] = cv::Vec2f(float(x), float(y));
  }
  return map;
}

WarpGrid framebufferGrid(cv::Size size, int step) {
  WarpGrid g;
  g.cols = (size.width - 1 + step - 1) / step + 1;
  g.rows = (size.height - 1 + step - 1) / step + 1;
  g.origin = Vec2(0, 0);
  g.step = Vec2(double(size.width - 1) / (g.cols - 1), double(size.height - 1) / (g.rows - 1));
  g.source.assign(static_cast<size_t>(g.cols) * g.rows, Vec2(kOutside, kOutside));
  return g;
}

Result<WarpMap> homographyMap(const Mat3& H, cv::Size output_size) {
  if (!finite(H) || output_size.width <= 0 || output_size.height <= 0) {
    return fail(ErrorCode::kInvalidInput, "homographyMap: non-finite H or empty output size");
  }
  // Scale-free singularity test: |det| relative to the product of row norms.
  const double scale = H.row(0).norm() * H.row(1).norm() * H.row(2).norm();
  if (scale == 0 || std::abs(H.determinant()) < 1e-12 * scale) {
    return fail(ErrorCode::kDegenerate, "homographyMap: H is singular");
  }
  const Mat3 Hinv = H.inverse();
  WarpMap map{cv::Mat(output_size, CV_32FC2)};
  // Rows on all threads: a handheld projector's keystone changes the map every frame.
  cv::parallel_for_(cv::Range(0, output_size.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      auto* row = map.xy.ptr<cv::Vec2f>(y);
      // Rows of the backward map are affine in x before the division: step incrementally
      // in double to keep the loop cheap and exact to double rounding.
      const Vec3 base = Hinv * Vec3(0, y, 1);
      const Vec3 dx = Hinv.col(0);
      for (int x = 0; x < output_size.width; ++x) {
        const Vec3 p = base + x * dx;
        if (!(p.z() > 0)) {
          row[x] = outside();
          continue;
        }
        const double sx = p.x() / p.z(), sy = p.y() / p.z();
        // Anything beyond +-1e6 px is outside every image; keep floats finite. This also
        // takes the points near the horizon (z <= 1e-12 |(x, y)| puts them beyond 1e11 px).
        if (!(std::abs(sx) <= 1e6 && std::abs(sy) <= 1e6)) {
          row[x] = outside();
        } else {
          row[x] = cv::Vec2f(float(sx), float(sy));
        }
      }
    }
  });
  return map;
}

Result<WarpMap> gridMap(const WarpGrid& grid, cv::Size output_size) {
  if (grid.cols < 2 || grid.rows < 2 ||
      grid.source.size() != static_cast<size_t>(grid.cols) * grid.rows || !(grid.step.x() > 0) ||
      !(grid.step.y() > 0) || !grid.origin.allFinite() || output_size.width <= 0 ||
      output_size.height <= 0) {
    return fail(ErrorCode::kInvalidInput, "gridMap: grid needs >= 2x2 nodes, positive steps");
  }
  for (const auto& s : grid.source) {
    if (!s.allFinite()) return fail(ErrorCode::kInvalidInput, "gridMap: non-finite node");
  }
  WarpMap map{cv::Mat(output_size, CV_32FC2)};
  for (int y = 0; y < output_size.height; ++y) {
    auto* row = map.xy.ptr<cv::Vec2f>(y);
    for (int x = 0; x < output_size.width; ++x) {
      const auto s = gridSource(grid, Vec2(x, y));
      row[x] = s ? cv::Vec2f(float(s->x()), float(s->y())) : outside();
    }
  }
  return map;
}

std::optional<Vec2> gridSource(const WarpGrid& grid, const Vec2& pixel) {
  if (grid.cols < 2 || grid.rows < 2 ||
      grid.source.size() != static_cast<size_t>(grid.cols) * grid.rows || !(grid.step.x() > 0) ||
      !(grid.step.y() > 0))
    return std::nullopt;
  const double gu = (pixel.x() - grid.origin.x()) / grid.step.x();
  const double gv = (pixel.y() - grid.origin.y()) / grid.step.y();
  if (!(gu >= 0 && gv >= 0 && gu <= grid.cols - 1 && gv <= grid.rows - 1)) return std::nullopt;
  const int i = std::min(static_cast<int>(gu), grid.cols - 2);
  const int j = std::min(static_cast<int>(gv), grid.rows - 2);
  const double u = gu - i, v = gv - j;
  const Vec2& s00 = grid.at(i, j);
  const Vec2& s11 = grid.at(i + 1, j + 1);
  // Two triangles per cell split along (i,j)-(i+1,j+1): affine inside each; a triangle
  // with a node no source reaches is not drawn (interpolating towards kOutside would
  // put far-off content next to the footprint's edge).
  const Vec2& s_mid = u >= v ? grid.at(i + 1, j) : grid.at(i, j + 1);
  if (s00.x() == kOutside || s11.x() == kOutside || s_mid.x() == kOutside) return std::nullopt;
  return u >= v ? Vec2(s00 + u * (s_mid - s00) + v * (s11 - s_mid))
                : Vec2(s00 + v * (s_mid - s00) + u * (s11 - s_mid));
}

Result<WarpMap> composeMaps(const WarpMap& first, const WarpMap& second) {
  if (first.xy.empty() || second.xy.empty() || first.xy.type() != CV_32FC2 ||
      second.xy.type() != CV_32FC2) {
    return fail(ErrorCode::kInvalidInput, "composeMaps: empty or non-CV_32FC2 map");
  }
  const int fw = first.xy.cols, fh = first.xy.rows;
  WarpMap out{cv::Mat(second.xy.size(), CV_32FC2)};
  for (int y = 0; y < second.xy.rows; ++y) {
    const auto* in = second.xy.ptr<cv::Vec2f>(y);
    auto* row = out.xy.ptr<cv::Vec2f>(y);
    for (int x = 0; x < second.xy.cols; ++x) {
      const cv::Vec2f q = in[x];
      if (isOutside(q) ||
          !(q[0] >= -0.5f && q[1] >= -0.5f && q[0] < fw - 0.5f && q[1] < fh - 0.5f)) {
        row[x] = outside();
        continue;
      }
      const int x0 = std::clamp(static_cast<int>(std::floor(q[0])), 0, fw - 1);
      const int y0 = std::clamp(static_cast<int>(std::floor(q[1])), 0, fh - 1);
      const int x1 = std::min(x0 + 1, fw - 1), y1 = std::min(y0 + 1, fh - 1);
      const float ax = std::clamp(q[0] - x0, 0.0f, 1.0f), ay = std::clamp(q[1] - y0, 0.0f, 1.0f);
      const cv::Vec2f a = first.xy.at<cv::Vec2f>(y0, x0), b = first.xy.at<cv::Vec2f>(y0, x1);
      const cv::Vec2f c = first.xy.at<cv::Vec2f>(y1, x0), d = first.xy.at<cv::Vec2f>(y1, x1);
      if (isOutside(a) || isOutside(b) || isOutside(c) || isOutside(d)) {
        // Next to the edge of `first`'s valid region: nearest entry, if valid.
        const cv::Vec2f n = first.xy.at<cv::Vec2f>(ay < 0.5f ? y0 : y1, ax < 0.5f ? x0 : x1);
        row[x] = n;
        continue;
      }
      row[x] = (a * (1 - ax) + b * ax) * (1 - ay) + (c * (1 - ax) + d * ax) * ay;
    }
  }
  return out;
}

}  // namespace procam::render
