#include "blend/curved_feather.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

namespace procam::blend {
namespace {

// A projector's weight nodes: from the first pixel centre to the last exactly, every
// `step` pixels or a little less, and the surface point each node's ray meets.
struct Lit {
  const SurfaceProjector* p = nullptr;
  const render::WarpGrid* drawn = nullptr;  // its lookup warp, when given
  render::PixelRays rays;
  int cols = 0, rows = 0;
  double sx = 1, sy = 1;                   // pixels between nodes
  std::vector<std::optional<Vec3>> point;  // per node, row-major
  cv::Mat distance;  // CV_32FC1, pixels to the nearest seam, padded by one pixel

  bool image(int i, int j) const {
    return i >= 0 && j >= 0 && i < cols && j < rows &&
           point[static_cast<std::size_t>(j) * cols + i].has_value();
  }
};

// Where projector `n` shows the surface point X, when it does: X inside its frame and
// its own ray through that pixel meeting its surface there.
std::optional<Vec2> pixelLighting(const Lit& n, const Vec3& X, double same_point_m) {
  const auto pixel = n.rays.framebufferPixelOf(X);
  if (!pixel) return std::nullopt;
  const Vec2 u = *pixel;
  if (!(u.x() >= -0.5 && u.y() >= -0.5 && u.x() <= n.p->size.width - 0.5 &&
        u.y() <= n.p->size.height - 0.5))
    return std::nullopt;
  if (n.drawn && !render::gridSource(*n.drawn, u)) return std::nullopt;
  const auto hit = n.p->surface->intersect(n.rays.through(u.x(), u.y()));
  if (!hit || (hit->point - X).norm() > same_point_m) return std::nullopt;
  return u;
}

// The seam distance of projector pixel u, bilinear between pixel centres.
double seamDistanceAt(const Lit& n, const Vec2& u) {
  const cv::Mat& d = n.distance;  // pixel (x, y) at (x + 1, y + 1)
  const double x = std::clamp(u.x() + 1, 0.0, d.cols - 1.0);
  const double y = std::clamp(u.y() + 1, 0.0, d.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), d.cols - 2);
  const int y0 = std::min(static_cast<int>(y), d.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = d.ptr<float>(y0);
  const float* r1 = d.ptr<float>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
         fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

// Distance of every pixel of projector m to the nearest edge of its image (the part of
// its frame whose rays meet the surface: a measured surface rarely reaches the frame's
// edge) past which another projector's image goes on. The image is known at the nodes
// (a pixel takes its nearest node's); every pixel outside it next to an image pixel
// whose node's surface point another projector lights is a seed, and a distance
// transform runs from the seeds at pixel resolution.
cv::Mat seamDistance(std::span<const Lit> lit, std::size_t m, double same_point_m) {
  const Lit& self = lit[m];
  const int w = self.p->size.width, h = self.p->size.height;
  // Per image node on the image's edge: whether another projector continues past it.
  std::vector<std::uint8_t> continued(self.point.size(), 0);
  for (int j = 0; j < self.rows; ++j) {
    for (int i = 0; i < self.cols; ++i) {
      if (!self.image(i, j)) continue;
      if (self.image(i - 1, j) && self.image(i + 1, j) && self.image(i, j - 1) &&
          self.image(i, j + 1))
        continue;
      const Vec3& X = *self.point[static_cast<std::size_t>(j) * self.cols + i];
      for (std::size_t n = 0; n < lit.size(); ++n) {
        if (n != m && pixelLighting(lit[n], X, same_point_m)) {
          continued[static_cast<std::size_t>(j) * self.cols + i] = 1;
          break;
        }
      }
    }
  }
  // Nearest node of every pixel, and the image at pixel resolution (padded by one).
  std::vector<int> node_x(w), node_y(h);
  for (int x = 0; x < w; ++x) node_x[x] = static_cast<int>(std::lround(x / self.sx));
  for (int y = 0; y < h; ++y) node_y[y] = static_cast<int>(std::lround(y / self.sy));
  auto nodeOf = [&](int x, int y) {
    return static_cast<std::size_t>(node_y[y]) * self.cols + node_x[x];
  };
  auto inImage = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && self.point[nodeOf(x, y)].has_value();
  };
  cv::Mat seeds(h + 2, w + 2, CV_8UC1, cv::Scalar(1));
  bool any = false;
  for (int y = -1; y <= h; ++y) {
    for (int x = -1; x <= w; ++x) {
      if (inImage(x, y)) continue;
      const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4; ++k) {
        const int nx = x + dx[k], ny = y + dy[k];
        if (inImage(nx, ny) && continued[nodeOf(nx, ny)]) {
          seeds.at<uchar>(y + 1, x + 1) = 0;
          any = true;
          break;
        }
      }
    }
  }
  if (!any) {
    // No edge is a seam: the projector is alone wherever it lights, or holds the others
    // inside its image; far from every seam everywhere.
    return cv::Mat(seeds.size(), CV_32FC1, cv::Scalar(float(4 * (w + h))));
  }
  cv::Mat distance;
  cv::distanceTransform(seeds, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance;
}

}  // namespace

Result<std::vector<render::PixelRays>> surfaceProjectorRays(
    std::span<const SurfaceProjector> projectors) {
  std::vector<render::PixelRays> rays;
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    const SurfaceProjector& p = projectors[m];
    const std::string name = "projector " + std::to_string(m);
    if (!p.surface) return fail(ErrorCode::kInvalidInput, name + " has no surface");
    if (p.size.width < 2 || p.size.height < 2 || p.size.width > 16384 || p.size.height > 16384)
      return fail(ErrorCode::kInvalidInput, name + ": bad framebuffer size");
    auto r = render::pixelRays(p.projector, p.post_warp);
    if (!r) return fail(ErrorCode::kInvalidInput, name + ": " + r.error().message);
    rays.push_back(*r);
  }
  return rays;
}

Result<std::vector<cv::Mat>> curvedFeatherWeights(std::span<const SurfaceProjector> projectors,
                                                  const CurvedFeatherOptions& options,
                                                  std::span<const render::WarpGrid> drawn) {
  if (projectors.empty()) return fail(ErrorCode::kInvalidInput, "feathering needs a projector");
  if (options.step < 1 || options.step > 64)
    return fail(ErrorCode::kInvalidInput, "feathering step outside [1, 64]");
  if (!(options.same_point_m > 0) || !std::isfinite(options.same_point_m))
    return fail(ErrorCode::kInvalidInput, "feathering: same_point_m must be positive");
  if (!drawn.empty() && drawn.size() != projectors.size())
    return fail(ErrorCode::kInvalidInput, "feathering: one lookup warp per projector, or none");
  auto rays = surfaceProjectorRays(projectors);
  if (!rays) return tl::unexpected(rays.error());
  std::vector<Lit> lit(projectors.size());
  for (std::size_t m = 0; m < projectors.size(); ++m) {
    Lit& l = lit[m];
    const cv::Size s = projectors[m].size;
    l.p = &projectors[m];
    l.drawn = drawn.empty() ? nullptr : &drawn[m];
    l.rays = (*rays)[m];
    l.cols = (s.width - 1 + options.step - 1) / options.step + 1;
    l.rows = (s.height - 1 + options.step - 1) / options.step + 1;
    l.sx = double(s.width - 1) / (l.cols - 1);
    l.sy = double(s.height - 1) / (l.rows - 1);
    l.point.resize(static_cast<std::size_t>(l.cols) * l.rows);
    cv::parallel_for_(cv::Range(0, l.rows), [&](const cv::Range& range) {
      for (int j = range.start; j < range.end; ++j) {
        for (int i = 0; i < l.cols; ++i) {
          const Vec2 u(i * l.sx, j * l.sy);
          if (l.drawn && !render::gridSource(*l.drawn, u)) continue;
          if (auto hit = l.p->surface->intersect(l.rays.through(u.x(), u.y())))
            l.point[static_cast<std::size_t>(j) * l.cols + i] = hit->point;
        }
      }
    });
  }
  for (std::size_t m = 0; m < lit.size(); ++m) {
    lit[m].distance = seamDistance(lit, m, options.same_point_m);
  }
  std::vector<cv::Mat> out;
  for (std::size_t m = 0; m < lit.size(); ++m) {
    const Lit& self = lit[m];
    const int w = self.p->size.width, h = self.p->size.height;
    cv::Mat nodes(self.rows, self.cols, CV_32FC1, cv::Scalar(0));
    cv::parallel_for_(cv::Range(0, self.rows), [&](const cv::Range& range) {
      for (int j = range.start; j < range.end; ++j) {
        for (int i = 0; i < self.cols; ++i) {
          const auto& X = self.point[static_cast<std::size_t>(j) * self.cols + i];
          if (!X) continue;
          const double own = seamDistanceAt(self, Vec2(i * self.sx, j * self.sy));
          double sum = own;
          for (std::size_t n = 0; n < lit.size(); ++n) {
            if (n == m) continue;
            if (auto v = pixelLighting(lit[n], *X, options.same_point_m)) {
              sum += seamDistanceAt(lit[n], *v);
            }
          }
          nodes.at<float>(j, i) = sum > 0 ? static_cast<float>(own / sum) : 0.0f;
        }
      }
    });
    // Weights bilinear between the nodes.
    cv::Mat map_x(h, w, CV_32FC1), map_y(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y) {
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        mx[x] = static_cast<float>(x / self.sx);
        my[x] = static_cast<float>(y / self.sy);
      }
    }
    cv::Mat weights;
    cv::remap(nodes, weights, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    out.push_back(std::move(weights));
  }
  return out;
}

}  // namespace procam::blend
