#include "blend/luminance_match.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "blend/node_grid.hpp"

namespace procam::blend {
namespace {

// The content raster: `cell` content pixels square, cell (0, 0) at the top-left corner.
struct Raster {
  double cell = 1;
  int nx = 0, ny = 0;
  std::optional<int> index(const Vec2& q) const {
    const int i = static_cast<int>(std::floor((q.x() + 0.5) / cell));
    const int j = static_cast<int>(std::floor((q.y() + 0.5) / cell));
    if (i < 0 || j < 0 || i >= nx || j >= ny) return std::nullopt;
    return j * nx + i;
  }
  // Bilinear between cell centres, clamped at the raster's edge.
  double at(const std::vector<double>& v, const Vec2& q) const {
    const cv::Mat_<double> grid(ny, nx, const_cast<double*>(v.data()));
    return sampleNodes(grid, (q.x() + 0.5) / cell - 0.5, (q.y() + 0.5) / cell - 0.5);
  }
};

// The largest t <= g with |t(a) - t(b)| <= step_cost per cell step (diagonals sqrt 2):
// two chamfer passes, exact for the 8-neighbour metric.
void limitGradient(const Raster& r, std::vector<double>& t, double step_cost) {
  const double diagonal = step_cost * std::sqrt(2.0);
  const auto relax = [&](int i, int j, int di, int dj, double cost) {
    const int x = i + di, y = j + dj;
    if (x < 0 || y < 0 || x >= r.nx || y >= r.ny) return;
    double& here = t[static_cast<std::size_t>(j) * r.nx + i];
    here = std::min(here, t[static_cast<std::size_t>(y) * r.nx + x] + cost);
  };
  for (int j = 0; j < r.ny; ++j) {
    for (int i = 0; i < r.nx; ++i) {
      relax(i, j, -1, 0, step_cost);
      relax(i, j, -1, -1, diagonal);
      relax(i, j, 0, -1, step_cost);
      relax(i, j, 1, -1, diagonal);
    }
  }
  for (int j = r.ny - 1; j >= 0; --j) {
    for (int i = r.nx - 1; i >= 0; --i) {
      relax(i, j, 1, 0, step_cost);
      relax(i, j, 1, 1, diagonal);
      relax(i, j, 0, 1, step_cost);
      relax(i, j, -1, 1, diagonal);
    }
  }
}

// Adds every sample of one projector to the raster. The display's white: its light w L
// and its weight w, each times the content area the sample stands for (|det| of the
// map's Jacobian over the sampling step), so that a cell the projector covers only in
// part counts only that part: num / den is the cell's mean display white. The bound:
// a projector scaled to light a point with T w / L reaches T only while T <= L / w,
// so the cell keeps the least L / w of its samples.
void accumulate(const MatchProjector& p, const Raster& r, int step, std::vector<double>& num,
                std::vector<double>& den, std::vector<double>& bound) {
  const cv::Mat& w = *p.weights;
  const int cols = (w.cols - 1) / step + 1, rows = (w.rows - 1) / step + 1;
  std::vector<std::optional<Vec2>> q(static_cast<std::size_t>(cols) * rows);
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      q[static_cast<std::size_t>(j) * cols + i] = p.to_content(Vec2(i * step, j * step));
    }
  }
  const auto at = [&](int i, int j) -> const std::optional<Vec2>& {
    return q[static_cast<std::size_t>(j) * cols + i];
  };
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const auto& c = at(i, j);
      if (!c) continue;
      const auto cell = r.index(*c);
      if (!cell) continue;
      const double weight = w.at<float>(j * step, i * step);
      if (!(weight > 0)) continue;
      const double light = brightnessAt(*p.brightness, Vec2(i * step, j * step));
      auto& least = bound[static_cast<std::size_t>(*cell)];
      least = std::min(least, light / weight);
      // Forward differences, backward on the last node or past the content's end.
      const int i2 = i + 1 < cols && at(i + 1, j) ? i + 1 : i - 1;
      const int j2 = j + 1 < rows && at(i, j + 1) ? j + 1 : j - 1;
      if (i2 < 0 || j2 < 0 || !at(i2, j) || !at(i, j2)) continue;
      const Vec2 dx = (*at(i2, j) - *c) / (i2 - i), dy = (*at(i, j2) - *c) / (j2 - j);
      const double area = std::abs(dx.x() * dy.y() - dx.y() * dy.x());
      num[static_cast<std::size_t>(*cell)] += weight * light * area;
      den[static_cast<std::size_t>(*cell)] += weight * area;
    }
  }
}

}  // namespace

Result<LuminanceMatch> matchLuminance(std::span<const MatchProjector> projectors, cv::Size content,
                                      const LuminanceMatchOptions& options) {
  if (projectors.empty()) return fail(ErrorCode::kInvalidInput, "luminance match: no projectors");
  if (content.width < 1 || content.height < 1 || options.cells < 16 || options.cells > 2048 ||
      !(options.gradient_per_px > 0) || !std::isfinite(options.gradient_per_px) ||
      options.sample_step < 1 || options.sample_step > 64) {
    return fail(ErrorCode::kInvalidInput, "luminance match: content size or options out of range");
  }
  for (const MatchProjector& p : projectors) {
    if (!p.weights || p.weights->type() != CV_32FC1 || p.weights->empty() || !p.brightness ||
        p.brightness->white.empty() || p.brightness->width != p.weights->cols ||
        p.brightness->height != p.weights->rows || !p.to_content) {
      return fail(ErrorCode::kInvalidInput,
                  "luminance match: every projector needs CV_32FC1 weights, a brightness map "
                  "of its framebuffer size and its content map");
    }
  }
  Raster r;
  r.cell = static_cast<double>(std::max(content.width, content.height)) / options.cells;
  r.nx = std::max(1, static_cast<int>(std::ceil(content.width / r.cell)));
  r.ny = std::max(1, static_cast<int>(std::ceil(content.height / r.cell)));
  const std::size_t n = static_cast<std::size_t>(r.nx) * r.ny;
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> num(n, 0), den(n, 0), bound(n, none);
  for (const MatchProjector& p : projectors) {
    accumulate(p, r, options.sample_step, num, den, bound);
  }

  LuminanceMatch out;
  out.figures.before_min = none;
  out.figures.after_min = none;
  std::vector<double> target(n, 0);
  std::vector<char> known(n, 0);
  double sum_before = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (!(den[k] > 1e-9) || !(num[k] > 0) || !std::isfinite(bound[k]) || !(bound[k] > 0)) continue;
    const double white = num[k] / den[k];
    out.figures.before_min = std::min(out.figures.before_min, white);
    out.figures.before_max = std::max(out.figures.before_max, white);
    sum_before += white;
    target[k] = std::log(bound[k]);
    known[k] = 1;
  }
  if (sum_before <= 0) {
    return fail(ErrorCode::kNotFound, "luminance match: no light lands on the content");
  }
  const std::vector<char> measured = known;
  cv::Mat_<double> cells(r.ny, r.nx, target.data());
  cv::Mat_<uchar> cells_known(r.ny, r.nx, reinterpret_cast<uchar*>(known.data()));
  fillFromKnownNeighbours(cells, cells_known);
  limitGradient(r, target, options.gradient_per_px * r.cell);
  double sum_after = 0;
  for (std::size_t k = 0; k < n; ++k) {
    target[k] = std::exp(target[k]);
    if (!measured[k]) continue;
    out.figures.after_min = std::min(out.figures.after_min, target[k]);
    out.figures.after_max = std::max(out.figures.after_max, target[k]);
    sum_after += target[k];
  }
  out.figures.kept = sum_after / sum_before;
  for (int j = 0; j < r.ny; ++j) {
    for (int i = 0; i < r.nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * r.nx + i;
      const auto step = [&](std::size_t other) {
        out.figures.largest_step = std::max(out.figures.largest_step,
                                            std::abs(std::log(target[other] / target[k])) / r.cell);
      };
      if (i + 1 < r.nx) step(k + 1);
      if (j + 1 < r.ny) step(k + r.nx);
    }
  }
  // Each projector lights its share w of the target: T w / L, so that the light of a
  // point sums to T wherever the weights sum to one, whatever their shape.
  for (const MatchProjector& p : projectors) {
    cv::Mat scaled = p.weights->clone();
    cv::parallel_for_(cv::Range(0, scaled.rows), [&](const cv::Range& rows) {
      for (int y = rows.start; y < rows.end; ++y) {
        float* row = scaled.ptr<float>(y);
        for (int x = 0; x < scaled.cols; ++x) {
          if (row[x] <= 0) continue;
          // A pixel that shows no content point has no share of the target either.
          const auto q = p.to_content(Vec2(x, y));
          const double share =
              q ? row[x] * r.at(target, *q) / brightnessAt(*p.brightness, Vec2(x, y)) : 0.0;
          row[x] = std::isfinite(share) ? static_cast<float>(std::clamp(share, 0.0, 1.0)) : 0.0f;
        }
      }
    });
    out.weights.push_back(std::move(scaled));
  }
  return out;
}

}  // namespace procam::blend
