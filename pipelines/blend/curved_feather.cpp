#include "blend/curved_feather.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

namespace procam::blend {
namespace {

struct Lit {
  const SurfaceProjector* p = nullptr;
  render::PixelRays rays;
  cv::Mat distance;  // CV_32FC1, (h + 2) x (w + 2): d to the nearest seam edge, pixel (x, y) at (x
                     // + 1, y + 1)
};

// Where projector `n` shows the surface point X, when it does.
std::optional<Vec2> pixelLighting(const Lit& n, const Vec3& X, double same_point_m) {
  const Vec3 x = n.p->projector * X.homogeneous();
  if (!(x.z() > 0)) return std::nullopt;
  const Vec2 u = x.hnormalized();
  if (!(u.x() >= -0.5 && u.y() >= -0.5 && u.x() <= n.p->size.width - 0.5 &&
        u.y() <= n.p->size.height - 0.5))
    return std::nullopt;
  const auto hit = n.p->surface->intersect(n.rays.through(u.x(), u.y()));
  if (!hit || (hit->point - X).norm() > same_point_m) return std::nullopt;
  return u;
}

float sampleDistance(const cv::Mat& d, const Vec2& u) {
  // Pixel centre (x, y) sits at (x + 1, y + 1) of the padded image.
  const double x = std::clamp(u.x() + 1, 0.0, d.cols - 1.0);
  const double y = std::clamp(u.y() + 1, 0.0, d.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), d.cols - 2),
            y0 = std::min(static_cast<int>(y), d.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = d.ptr<float>(y0);
  const float* r1 = d.ptr<float>(y0 + 1);
  return static_cast<float>((1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
                            fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]));
}

// Distance of every pixel of projector m to the nearest frame edge past which another
// projector's image goes on: zeros just outside the border pixels whose surface point
// another projector lights, a distance transform from them.
cv::Mat seamDistance(std::span<const Lit> lit, std::size_t m, double same_point_m) {
  const Lit& self = lit[m];
  const int w = self.p->size.width, h = self.p->size.height;
  cv::Mat seeds(h + 2, w + 2, CV_8UC1, cv::Scalar(1));
  auto continued = [&](int x, int y) {
    const auto hit = self.p->surface->intersect(self.rays.through(x, y));
    if (!hit) return false;
    for (std::size_t n = 0; n < lit.size(); ++n) {
      if (n != m && pixelLighting(lit[n], hit->point, same_point_m)) return true;
    }
    return false;
  };
  bool any = false;
  for (int x = 0; x < w; ++x) {
    if (continued(x, 0)) any = true, seeds.at<uchar>(0, x + 1) = 0;
    if (continued(x, h - 1)) any = true, seeds.at<uchar>(h + 1, x + 1) = 0;
  }
  for (int y = 0; y < h; ++y) {
    if (continued(0, y)) any = true, seeds.at<uchar>(y + 1, 0) = 0;
    if (continued(w - 1, y)) any = true, seeds.at<uchar>(y + 1, w + 1) = 0;
  }
  cv::Mat distance;
  if (!any) {
    // No edge is a seam: the projector is alone wherever it lights, or holds the others
    // inside its image; far from every seam everywhere.
    return cv::Mat(h + 2, w + 2, CV_32FC1, cv::Scalar(float(4 * (w + h))));
  }
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
    auto r = render::pixelRays(p.projector);
    if (!r) return fail(ErrorCode::kInvalidInput, name + ": " + r.error().message);
    rays.push_back(*r);
  }
  return rays;
}

Result<std::vector<cv::Mat>> curvedFeatherWeights(std::span<const SurfaceProjector> projectors,
                                                  const CurvedFeatherOptions& options) {
  if (projectors.empty()) return fail(ErrorCode::kInvalidInput, "feathering needs a projector");
  if (options.step < 1 || options.step > 64)
    return fail(ErrorCode::kInvalidInput, "feathering step outside [1, 64]");
  if (!(options.same_point_m > 0) || !std::isfinite(options.same_point_m))
    return fail(ErrorCode::kInvalidInput, "feathering: same_point_m must be positive");
  auto rays = surfaceProjectorRays(projectors);
  if (!rays) return tl::unexpected(rays.error());
  std::vector<Lit> lit(projectors.size());
  for (std::size_t m = 0; m < projectors.size(); ++m) lit[m] = {&projectors[m], (*rays)[m], {}};
  for (std::size_t m = 0; m < lit.size(); ++m) {
    lit[m].distance = seamDistance(lit, m, options.same_point_m);
  }
  std::vector<cv::Mat> out;
  for (std::size_t m = 0; m < lit.size(); ++m) {
    const Lit& self = lit[m];
    const int w = self.p->size.width, h = self.p->size.height;
    // Nodes from the first pixel centre to the last exactly, weights bilinear between.
    const int cols = (w - 1 + options.step - 1) / options.step + 1;
    const int rows = (h - 1 + options.step - 1) / options.step + 1;
    const double sx = double(w - 1) / (cols - 1), sy = double(h - 1) / (rows - 1);
    cv::Mat nodes(rows, cols, CV_32FC1, cv::Scalar(0));
    cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
      for (int j = range.start; j < range.end; ++j) {
        for (int i = 0; i < cols; ++i) {
          const Vec2 u(i * sx, j * sy);
          const auto hit = self.p->surface->intersect(self.rays.through(u.x(), u.y()));
          if (!hit) continue;
          const double own = sampleDistance(self.distance, u);
          double sum = own;
          for (std::size_t n = 0; n < lit.size(); ++n) {
            if (n == m) continue;
            if (auto v = pixelLighting(lit[n], hit->point, options.same_point_m)) {
              sum += sampleDistance(lit[n].distance, *v);
            }
          }
          nodes.at<float>(j, i) = sum > 0 ? static_cast<float>(own / sum) : 0.0f;
        }
      }
    });
    cv::Mat map_x(h, w, CV_32FC1), map_y(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y) {
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        mx[x] = static_cast<float>(x / sx);
        my[x] = static_cast<float>(y / sy);
      }
    }
    cv::Mat weights;
    cv::remap(nodes, weights, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    out.push_back(std::move(weights));
  }
  return out;
}

}  // namespace procam::blend
