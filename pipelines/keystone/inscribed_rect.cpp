#include "keystone/inscribed_rect.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace procam::keystone {
namespace {

// Constraint g·(c_x, c_y, h) <= b.
struct Row {
  Eigen::Vector3d g;
  double b;
};

// Feasibility slack in normalised coordinates (polygon scaled to unit extent).
constexpr double kTol = 1e-9;

double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Andrew's monotone chain; collinear and duplicate points dropped. CCW order.
std::vector<Vec2> convexHull(std::vector<Vec2> pts) {
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (pts.size() < 3) {
    if (pts.size() == 2 && (pts[0] - pts[1]).norm() < kTol) pts.pop_back();
    return pts;
  }
  std::vector<Vec2> hull(2 * pts.size());
  std::size_t k = 0;
  auto turn = [&](const Vec2& p) {
    while (k >= 2 && cross(hull[k - 1] - hull[k - 2], p - hull[k - 2]) <= kTol * kTol) --k;
    hull[k++] = p;
  };
  for (const Vec2& p : pts) turn(p);
  const std::size_t lower = k + 1;
  for (std::size_t i = pts.size() - 1; i-- > 0;) {
    const Vec2& p = pts[i];
    while (k >= lower && cross(hull[k - 1] - hull[k - 2], p - hull[k - 2]) <= kTol * kTol) --k;
    hull[k++] = p;
  }
  hull.resize(k - 1);
  if (hull.size() == 2 && (hull[0] - hull[1]).norm() < kTol) hull.pop_back();
  return hull;
}

Vec2 closestOnSegment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double len2 = d.squaredNorm();
  if (len2 == 0) return a;
  return a + std::clamp((p - a).dot(d) / len2, 0.0, 1.0) * d;
}

// Closest point of a convex polygon (CCW hull; 1 or 2 points allowed) to p.
Vec2 projectOntoHull(const Vec2& p, const std::vector<Vec2>& hull) {
  if (hull.size() == 1) return hull[0];
  if (hull.size() >= 3) {
    bool inside = true;
    for (std::size_t i = 0; i < hull.size(); ++i)
      inside = inside && cross(hull[(i + 1) % hull.size()] - hull[i], p - hull[i]) >= 0;
    if (inside) return p;
  }
  Vec2 best = hull[0];
  double best_d = 1e300;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vec2 q = closestOnSegment(p, hull[i], hull[(i + 1) % hull.size()]);
    if ((q - p).squaredNorm() < best_d) {
      best_d = (q - p).squaredNorm();
      best = q;
    }
  }
  return best;
}

bool feasible(const std::vector<Row>& rows, const Eigen::Vector3d& x) {
  return std::all_of(rows.begin(), rows.end(),
                     [&](const Row& r) { return r.g.dot(x) <= r.b + kTol; });
}

// Vertices of {c : n_i·c <= b_i - h w_i} (pairwise intersections that satisfy all).
std::vector<Vec2> centreRegion(const std::vector<Row>& rows, double h) {
  std::vector<Vec2> pts;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = i + 1; j < rows.size(); ++j) {
      Eigen::Matrix2d M;
      M << rows[i].g.x(), rows[i].g.y(), rows[j].g.x(), rows[j].g.y();
      if (std::abs(M.determinant()) < 1e-12) continue;
      const Vec2 c =
          M.inverse() * Vec2(rows[i].b - h * rows[i].g.z(), rows[j].b - h * rows[j].g.z());
      if (feasible(rows, Eigen::Vector3d(c.x(), c.y(), h))) pts.push_back(c);
    }
  return convexHull(std::move(pts));
}

}  // namespace

Result<AxisRect> largestInscribedRect(std::span<const Vec2> polygon, double aspect,
                                      const InscribeOptions& options) {
  if (polygon.size() < 3) return fail(ErrorCode::kInvalidInput, "polygon needs >= 3 vertices");
  if (!std::isfinite(aspect) || aspect <= 0)
    return fail(ErrorCode::kInvalidInput, "aspect ratio must be finite and > 0");
  if (!(options.zoom > 0 && options.zoom <= 1))
    return fail(ErrorCode::kInvalidInput, "zoom must be in (0, 1]");
  if (options.previous_centre && !options.previous_centre->allFinite())
    return fail(ErrorCode::kInvalidInput, "previous centre is not finite");
  for (const Vec2& p : polygon)
    if (!p.allFinite()) return fail(ErrorCode::kInvalidInput, "polygon vertex is not finite");

  // Normalise: centroid at the origin, unit extent (conditioning of the small solves).
  Vec2 mean = Vec2::Zero();
  for (const Vec2& p : polygon) mean += p;
  mean /= double(polygon.size());
  double extent = 0;
  for (const Vec2& p : polygon) extent = std::max(extent, (p - mean).cwiseAbs().maxCoeff());
  if (extent <= 0) return fail(ErrorCode::kDegenerate, "polygon has zero extent");
  std::vector<Vec2> q;
  for (const Vec2& p : polygon) q.push_back((p - mean) / extent);

  const std::size_t m = q.size();
  double area2 = 0;
  for (std::size_t i = 0; i < m; ++i) area2 += cross(q[i], q[(i + 1) % m]);
  if (std::abs(area2) < 1e-12) return fail(ErrorCode::kDegenerate, "polygon has zero area");
  const double winding = area2 > 0 ? 1.0 : -1.0;
  std::vector<Row> rows;
  for (std::size_t i = 0; i < m; ++i) {
    const Vec2 e = q[(i + 1) % m] - q[i];
    if (winding * cross(e, q[(i + 2) % m] - q[(i + 1) % m]) < -1e-12)
      return fail(ErrorCode::kDegenerate, "polygon is not convex");
    if (e.norm() < 1e-12) continue;                           // repeated vertex
    const Vec2 n = winding * Vec2(e.y(), -e.x()) / e.norm();  // outward
    rows.push_back(
        {Eigen::Vector3d(n.x(), n.y(), aspect * std::abs(n.x()) + std::abs(n.y())), n.dot(q[i])});
  }

  // Stage 1: max h over the vertices of the LP (three active constraints).
  double h_best = -1;
  std::vector<Eigen::Vector3d> vertices;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = i + 1; j < rows.size(); ++j)
      for (std::size_t k = j + 1; k < rows.size(); ++k) {
        Eigen::Matrix3d M;
        M << rows[i].g.transpose(), rows[j].g.transpose(), rows[k].g.transpose();
        if (std::abs(M.determinant()) < 1e-12) continue;
        const Eigen::Vector3d x =
            M.partialPivLu().solve(Eigen::Vector3d(rows[i].b, rows[j].b, rows[k].b));
        if (!feasible(rows, x) || x.z() <= 0) continue;
        vertices.push_back(x);
        h_best = std::max(h_best, x.z());
      }
  if (h_best <= 0) return fail(ErrorCode::kDegenerate, "no rectangle fits inside the polygon");

  // The optimal centres form a point or a segment; its midpoint is the centred choice.
  std::vector<Vec2> optimal;
  for (const auto& v : vertices)
    if (v.z() >= h_best - kTol) optimal.push_back(v.head<2>());
  const std::vector<Vec2> opt_hull = convexHull(optimal);
  Vec2 centred = opt_hull[0];
  double far = -1;
  for (const Vec2& a : opt_hull)
    for (const Vec2& b : opt_hull)
      if ((a - b).norm() > far) {
        far = (a - b).norm();
        centred = 0.5 * (a + b);
      }

  const double h = options.zoom * h_best;
  const std::vector<Vec2> region = options.zoom < 1 ? centreRegion(rows, h) : opt_hull;
  Vec2 c = centred;
  if (options.anchor == Anchor::kTop && !region.empty()) {
    double top = -1e300;
    for (const Vec2& p : region) top = std::max(top, p.y());
    std::vector<Vec2> top_pts;
    for (const Vec2& p : region)
      if (p.y() >= top - kTol) top_pts.push_back(p);
    const std::vector<Vec2> top_hull = convexHull(top_pts);
    c = projectOntoHull(Vec2(centred.x(), top), top_hull);
  } else if (options.anchor == Anchor::kKeepPrevious && options.previous_centre &&
             !region.empty()) {
    c = projectOntoHull((*options.previous_centre - mean) / extent, region);
  }

  AxisRect out;
  out.centre = mean + extent * c;
  out.half_height = extent * h;
  out.half_width = aspect * out.half_height;
  return out;
}

}  // namespace procam::keystone
