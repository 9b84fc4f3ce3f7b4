#include "render/viewer_view.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace procam::render {
namespace {}  // namespace

Result<PixelRays> pixelRays(const Mat34& P, std::shared_ptr<const WarpGrid> post_warp) {
  const Mat3 M = P.leftCols<3>();
  if (!P.allFinite() || std::abs(M.determinant()) < 1e-300) {
    return fail(ErrorCode::kInvalidInput, "viewer view: singular projector matrix");
  }
  const Mat3 Minv = M.inverse();
  return PixelRays{Minv, -Minv * P.col(3), std::move(post_warp), M};
}

Vec2 PixelRays::toPinhole(const Vec2& pixel) const {
  if (!post_warp || post_warp->cols < 2 || post_warp->rows < 2) return pixel;
  const WarpGrid& g = *post_warp;
  const Vec2 last = g.node(g.cols - 1, g.rows - 1);
  const Vec2 at = pixel.cwiseMax(g.origin).cwiseMin(last);
  const auto to = gridSource(g, at);
  return to ? Vec2(pixel + (*to - at)) : pixel;
}

Vec2 PixelRays::toFramebuffer(const Vec2& pinhole) const {
  if (!post_warp) return pinhole;
  Vec2 pixel = pinhole;
  for (int it = 0; it < 4; ++it) pixel -= toPinhole(pixel) - pinhole;
  return pixel;
}

std::optional<Vec2> PixelRays::framebufferPixelOf(const Vec3& X) const {
  const Vec3 x = M * (X - centre);
  if (!(x.z() > 0)) return std::nullopt;
  return toFramebuffer(x.hnormalized());
}

Result<Mat3> uprightEyeRotation(const Vec3& forward) {
  const Vec3 f = forward.normalized();
  Vec3 r = f.cross(Vec3::UnitZ());
  if (!f.allFinite() || r.norm() < 1e-6) {
    return fail(ErrorCode::kDegenerate, "viewer view: the eye looks straight up or down");
  }
  r.normalize();
  const Vec3 d = f.cross(r);
  Mat3 R;
  R.row(0) = r.transpose();
  R.row(1) = d.transpose();
  R.row(2) = f.transpose();
  return R;
}

Mat34 contentViewMatrix(const Mat3& R, const Vec3& eye, const keystone::AxisRect& rect,
                        cv::Size content) {
  // u + 0.5 = (x - left) * W / width, and v + 0.5 = (top - y_up) * H / height; the
  // plane's y down is the content's v down (y_up = -y).
  const double s = content.width / (2 * rect.half_width);
  const double left = rect.centre.x() - rect.half_width, top = rect.centre.y() + rect.half_height;
  Mat3 K;
  K << s, 0, -left * s - 0.5, 0, s, top * s - 0.5, 0, 0, 1;
  Mat34 Rt;
  Rt.leftCols<3>() = R;
  Rt.col(3) = -R * eye;
  return K * Rt;
}

Result<Mat34> viewerContentMatrix(const geom::MeshIntersector& surface, const Mat34& projector,
                                  cv::Size size, const Vec3& eye, cv::Size content) {
  if (size.width < 2 || size.height < 2 || content.width < 2 || content.height < 2 ||
      !eye.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "viewer view: bad sizes or eye");
  }
  auto rays = pixelRays(projector);
  if (!rays) return tl::unexpected(rays.error());
  const auto centre_hit =
      surface.intersect(rays->through(0.5 * (size.width - 1), 0.5 * (size.height - 1)));
  if (!centre_hit) {
    return fail(ErrorCode::kDegenerate, "viewer view: the projector's centre misses the surface");
  }
  // Eye frame: x right, y down, z towards the footprint's centre; world +Z up.
  auto turned = uprightEyeRotation(centre_hit->point - eye);
  if (!turned) return tl::unexpected(turned.error());
  const Mat3& R = *turned;
  // The footprint's border as the eye sees it, on the plane z = 1 (y up for the
  // rectangle solver).
  constexpr int kPerSide = 48;
  std::vector<cv::Point2f> border;
  const double x1 = size.width - 0.5, y1 = size.height - 0.5;
  // A point of the frame's edge, or where the surface begins on the way from it to the
  // frame's centre (a measured surface rarely reaches the frame's edge).
  const Vec2 mid(0.5 * (size.width - 1), 0.5 * (size.height - 1));
  auto sample = [&](double x, double y) -> bool {
    for (int k = 0; k < 64; ++k) {
      const Vec2 p = Vec2(x, y) + (k / 64.0) * (mid - Vec2(x, y));
      const auto hit = surface.intersect(rays->through(p.x(), p.y()));
      if (!hit) continue;
      const Vec3 q = R * (hit->point - eye);
      if (q.z() <= 1e-9) return false;
      border.emplace_back(float(q.x() / q.z()), float(-q.y() / q.z()));
      return true;
    }
    return true;  // nothing on this line: the footprint is bounded by the others
  };
  bool seen = true;
  for (int i = 0; i < kPerSide; ++i) {
    const double a = double(i) / kPerSide;
    seen = seen && sample(-0.5 + a * size.width, -0.5);
    seen = seen && sample(x1, -0.5 + a * size.height);
    seen = seen && sample(x1 - a * size.width, y1);
    seen = seen && sample(-0.5, y1 - a * size.height);
  }
  if (!seen)
    return fail(ErrorCode::kDegenerate, "viewer view: part of the footprint is behind the eye");
  if (border.size() < kPerSide) {
    return fail(ErrorCode::kDegenerate,
                "viewer view: too little of the footprint is on the surface (" +
                    std::to_string(border.size()) + " of " + std::to_string(4 * kPerSide) +
                    " edge samples)");
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(border, hull);
  std::vector<Vec2> polygon;
  for (const auto& p : hull) polygon.emplace_back(p.x, p.y);
  const double aspect = double(content.width) / content.height;
  auto rect = keystone::largestInscribedRect(polygon, aspect);
  if (!rect) return tl::unexpected(rect.error());
  // The footprint seen over a fold, or a measured surface with holes, need not be convex:
  // shrink about the centre until every point of the rectangle's border is shown, i.e. the
  // eye's ray through it meets the surface at a point inside the projector's frame.
  auto shown = [&](double x, double y_up) {
    const auto hit = surface.intersect({eye, (R.transpose() * Vec3(x, -y_up, 1)).normalized()});
    if (!hit) return false;
    const Vec3 p = projector * hit->point.homogeneous();
    if (p.z() <= 0) return false;
    const double u = p.x() / p.z(), v = p.y() / p.z();
    return u >= -0.5 && v >= -0.5 && u <= size.width - 0.5 && v <= size.height - 0.5;
  };
  keystone::AxisRect fit = *rect;
  for (int iteration = 0; iteration < 80; ++iteration) {
    bool inside = true;
    for (int i = 0; i < 16 && inside; ++i) {
      const double a = -1 + 2.0 * i / 16;
      for (const Vec2& c : {Vec2(a, -1), Vec2(1, a), Vec2(-a, 1), Vec2(-1, -a)}) {
        if (!shown(fit.centre.x() + c.x() * fit.half_width,
                   fit.centre.y() + c.y() * fit.half_height)) {
          inside = false;
          break;
        }
      }
    }
    if (inside) break;
    fit.half_width *= 0.98;
    fit.half_height *= 0.98;
  }
  const Mat34 V = contentViewMatrix(R, eye, fit, content);
  if (!V.allFinite()) return fail(ErrorCode::kDegenerate, "viewer view: degenerate rectangle");
  return V;
}

Result<WarpGrid> lookupGridThrough(
    const geom::MeshIntersector& surface, const Mat34& projector, cv::Size size, int step,
    std::shared_ptr<const WarpGrid> post_warp,
    const std::function<std::optional<Vec2>(const Vec3&)>& to_content) {
  if (size.width < 2 || size.height < 2 || step < 1) {
    return fail(ErrorCode::kInvalidInput, "lookup grid: bad size or step");
  }
  auto rays = pixelRays(projector, std::move(post_warp));
  if (!rays) return tl::unexpected(rays.error());
  WarpGrid g = framebufferGrid(size, step);
  cv::parallel_for_(cv::Range(0, g.rows), [&](const cv::Range& range) {
    for (int j = range.start; j < range.end; ++j) {
      for (int i = 0; i < g.cols; ++i) {
        const Vec2 n = g.node(i, j);
        const auto hit = surface.intersect(rays->through(n.x(), n.y()));
        if (!hit) continue;
        if (const auto c = to_content(hit->point))
          g.source[static_cast<size_t>(j) * g.cols + i] = *c;
      }
    }
  });
  return g;
}

Result<WarpGrid> lookupGridForViewer(const geom::MeshIntersector& surface, const Mat34& projector,
                                     cv::Size size, const Mat34& viewer, int step,
                                     std::shared_ptr<const WarpGrid> post_warp) {
  if (!viewer.allFinite()) return fail(ErrorCode::kInvalidInput, "lookup grid: bad viewer");
  return lookupGridThrough(surface, projector, size, step, std::move(post_warp),
                           [&viewer](const Vec3& X) -> std::optional<Vec2> {
                             const Vec3 q = viewer * X.homogeneous();
                             if (q.z() <= 0) return std::nullopt;
                             return q.hnormalized();
                           });
}

}  // namespace procam::render
