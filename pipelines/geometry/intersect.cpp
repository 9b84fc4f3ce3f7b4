#include "geometry/intersect.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "geometry/mesh_bvh.hpp"

namespace procam::geom {
namespace {

// Below this sine of the angle at a vertex a triangle counts as degenerate (see
// intersectTriangle).
constexpr double kMinTriangleSine = 1e-8;

bool finite(const Vec3& v) {
  return v.allFinite();
}

// A ray usable by every test: finite origin, finite non-zero direction and a
// non-empty finite-or-infinite range. Anything else misses instead of producing NaN.
bool usable(const Ray& ray, const RayRange& range) {
  return finite(ray.origin) && finite(ray.dir) && ray.dir.squaredNorm() > 0 &&
         !std::isnan(range.t_min) && !std::isnan(range.t_max) && range.t_min < range.t_max;
}

bool inRange(double t, const RayRange& range) {
  return std::isfinite(t) && t > range.t_min && t < range.t_max;
}

// Builds the hit record: unit normal turned to face against the ray.
std::optional<Hit> makeHit(const Ray& ray, double t, Vec3 normal, std::uint32_t primitive) {
  const double len = normal.norm();
  if (!(len > 0) || !std::isfinite(len)) return std::nullopt;
  normal /= len;
  if (normal.dot(ray.dir) > 0) normal = -normal;
  Hit hit;
  hit.t = t;
  hit.point = ray.at(t);
  hit.normal = normal;
  hit.primitive = primitive;
  if (!finite(hit.point)) return std::nullopt;
  return hit;
}

// Roots of s^2 + 2 b s + c = 0 given disc = b^2 - c >= 0 computed in a stable
// way by the caller. The larger-magnitude root comes from -b - sgn(b) sqrt(disc)
// and the other from c / q, which avoids the cancellation of the textbook formula.
std::pair<double, double> stableRoots(double b, double c, double disc) {
  const double root = std::sqrt(disc);
  const double q = b >= 0 ? -b - root : -b + root;
  if (q == 0) return {0.0, 0.0};
  double s1 = q;
  double s2 = c / q;
  if (s1 > s2) std::swap(s1, s2);
  return {s1, s2};
}

}  // namespace

std::optional<Hit> intersectPlane(const Ray& ray, const Plane& plane, RayRange range) {
  if (!usable(ray, range) || !finite(plane.n) || !std::isfinite(plane.d)) return std::nullopt;
  const double denom = plane.n.dot(ray.dir);
  if (denom == 0 || !std::isfinite(denom)) return std::nullopt;  // parallel: no single point
  const double t = -plane.signedDistance(ray.origin) / denom;
  if (!inRange(t, range)) return std::nullopt;
  return makeHit(ray, t, plane.n, 0);
}

std::optional<Hit> intersectRectangle(const Ray& ray, const Rectangle& rect, RayRange range) {
  if (!usable(ray, range) || !finite(rect.origin) || !finite(rect.u) || !finite(rect.v)) {
    return std::nullopt;
  }
  const double uu = rect.u.squaredNorm();
  const double vv = rect.v.squaredNorm();
  const Vec3 n = rect.u.cross(rect.v);
  if (!(uu > 0) || !(vv > 0) || !(n.squaredNorm() > 0)) return std::nullopt;
  const double denom = n.dot(ray.dir);
  if (denom == 0 || !std::isfinite(denom)) return std::nullopt;
  const Vec3 rel = ray.origin - rect.origin;
  const double t = -n.dot(rel) / denom;
  if (!inRange(t, range)) return std::nullopt;
  const Vec3 local = rel + t * ray.dir;
  const double a = local.dot(rect.u) / uu;
  const double b = local.dot(rect.v) / vv;
  if (!(a >= 0 && a <= 1 && b >= 0 && b <= 1)) return std::nullopt;
  return makeHit(ray, t, n, 0);
}

std::optional<Hit> intersectBox(const Ray& ray, const Box& box, RayRange range) {
  if (!usable(ray, range) || !finite(box.center) || !finite(box.half) || !box.axes.allFinite() ||
      !(box.half.minCoeff() >= 0)) {
    return std::nullopt;
  }
  // Slab test in the box frame. Entry and exit faces are tracked so that a ray
  // starting inside (or with the entry behind t_min) reports the exit face.
  const Vec3 o = box.axes.transpose() * (ray.origin - box.center);
  const Vec3 d = box.axes.transpose() * ray.dir;
  double t_enter = -INFINITY, t_exit = INFINITY;
  int enter_face = -1, exit_face = -1;
  for (int i = 0; i < 3; ++i) {
    const double h = box.half[i];
    if (d[i] == 0) {
      if (o[i] < -h || o[i] > h) return std::nullopt;
      continue;  // parallel to this slab and inside it: no constraint
    }
    double t0 = (-h - o[i]) / d[i];
    double t1 = (h - o[i]) / d[i];
    int f0 = 2 * i, f1 = 2 * i + 1;  // face 2i: -axis i, face 2i+1: +axis i
    if (t0 > t1) {
      std::swap(t0, t1);
      std::swap(f0, f1);
    }
    if (t0 > t_enter) {
      t_enter = t0;
      enter_face = f0;
    }
    if (t1 < t_exit) {
      t_exit = t1;
      exit_face = f1;
    }
  }
  if (t_enter > t_exit) return std::nullopt;
  double t = t_enter;
  int face = enter_face;
  if (!inRange(t, range)) {
    t = t_exit;
    face = exit_face;
    if (!inRange(t, range)) return std::nullopt;
  }
  if (face < 0) return std::nullopt;
  const Vec3 normal = box.axes.col(face / 2) * ((face % 2) ? 1.0 : -1.0);
  return makeHit(ray, t, normal, static_cast<std::uint32_t>(face));
}

std::optional<Hit> intersectCylinder(const Ray& ray, const Cylinder& cyl, RayRange range) {
  if (!usable(ray, range) || !finite(cyl.base) || !finite(cyl.axis) || !std::isfinite(cyl.radius) ||
      !std::isfinite(cyl.height) || !(cyl.radius > 0) || !(cyl.height >= 0)) {
    return std::nullopt;
  }
  const double axis_len = cyl.axis.norm();
  if (!(axis_len > 0)) return std::nullopt;
  const Vec3 a = cyl.axis / axis_len;
  const double dir_len = ray.dir.norm();
  const Vec3 dn = ray.dir / dir_len;
  // Work in the plane perpendicular to the axis, along the unit projected direction,
  // so the discriminant is r^2 - (distance of closest approach)^2 without cancellation.
  const Vec3 w = ray.origin - cyl.base;
  const Vec3 wp = w - w.dot(a) * a;
  const Vec3 dp = dn - dn.dot(a) * a;
  const double dp_len = dp.norm();
  if (!(dp_len > 0)) return std::nullopt;  // ray parallel to the axis never meets the wall once
  const Vec3 u = dp / dp_len;
  const double b = wp.dot(u);
  const Vec3 closest = wp - b * u;
  const double r2 = cyl.radius * cyl.radius;
  const double disc = r2 - closest.squaredNorm();
  if (disc < 0) return std::nullopt;
  const auto [s1, s2] = stableRoots(b, wp.squaredNorm() - r2, disc);
  for (const double s : {s1, s2}) {
    // s is a length along u; the ray advances dp_len along u per unit of distance.
    const double t = s / dp_len / dir_len;
    if (!inRange(t, range)) continue;
    const Vec3 rel = w + t * ray.dir;
    const double along = rel.dot(a);
    if (!(along >= 0 && along <= cyl.height)) continue;
    return makeHit(ray, t, rel - along * a, 0);
  }
  return std::nullopt;
}

std::optional<Hit> intersectSphere(const Ray& ray, const Sphere& sphere, RayRange range) {
  if (!usable(ray, range) || !finite(sphere.center) || !std::isfinite(sphere.radius) ||
      !(sphere.radius > 0) || !finite(sphere.cap_axis) || std::isnan(sphere.cap_min)) {
    return std::nullopt;
  }
  const double cap_len = sphere.cap_axis.norm();
  if (!(cap_len > 0)) return std::nullopt;
  const Vec3 cap = sphere.cap_axis / cap_len;
  const double dir_len = ray.dir.norm();
  const Vec3 dn = ray.dir / dir_len;
  const Vec3 f = ray.origin - sphere.center;
  const double b = f.dot(dn);
  const Vec3 closest = f - b * dn;  // discriminant from the closest approach (no cancellation)
  const double r2 = sphere.radius * sphere.radius;
  const double disc = r2 - closest.squaredNorm();
  if (disc < 0) return std::nullopt;
  const auto [s1, s2] = stableRoots(b, f.squaredNorm() - r2, disc);
  for (const double s : {s1, s2}) {
    const double t = s / dir_len;
    if (!inRange(t, range)) continue;
    const Vec3 rel = f + t * ray.dir;
    if (!(rel.dot(cap) >= sphere.cap_min)) continue;
    return makeHit(ray, t, rel, 0);
  }
  return std::nullopt;
}

std::optional<Hit> intersectTriangle(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c,
                                     RayRange range) {
  if (!usable(ray, range) || !finite(a) || !finite(b) || !finite(c)) return std::nullopt;
  const Vec3 e1 = b - a;
  const Vec3 e2 = c - a;
  const Vec3 n = e1.cross(e2);
  const double n_len = n.norm();
  // Degenerate triangle: the plane of a sliver is known only to eps / sin(angle at a),
  // and the hit with it to that times t; below sin = 1e-8 it counts as zero area.
  if (!(n_len > kMinTriangleSine * e1.norm() * e2.norm())) return std::nullopt;
  const Vec3 p = ray.dir.cross(e2);
  const double det = e1.dot(p);  // = -dir . n
  // Parallel or grazing within rounding: the hit point would be pure noise.
  if (!(std::abs(det) > 1e-12 * n_len * ray.dir.norm())) return std::nullopt;
  const double inv = 1.0 / det;
  const Vec3 s = ray.origin - a;
  // Edges belong to both triangles that share them, within rounding: a ray along a mesh's
  // inner edge (a post-rendering warp sends node rays exactly along the images of the
  // mesh's edges) would otherwise miss both.
  constexpr double kEdge = 1e-13;
  const double u = s.dot(p) * inv;
  if (!(u >= -kEdge && u <= 1 + kEdge)) return std::nullopt;
  const Vec3 q = s.cross(e1);
  const double v = ray.dir.dot(q) * inv;
  if (!(v >= -kEdge && u + v <= 1 + kEdge)) return std::nullopt;
  const double t = e2.dot(q) * inv;
  if (!inRange(t, range)) return std::nullopt;
  return makeHit(ray, t, n, 0);
}

struct MeshIntersector::Impl {
  TriangleMesh mesh;
  std::optional<MeshBvh> bvh;
};

MeshIntersector::MeshIntersector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MeshIntersector::MeshIntersector(MeshIntersector&&) noexcept = default;
MeshIntersector& MeshIntersector::operator=(MeshIntersector&&) noexcept = default;
MeshIntersector::~MeshIntersector() = default;

Result<MeshIntersector> MeshIntersector::build(TriangleMesh mesh) {
  for (const Vec3& v : mesh.vertices) {
    if (!finite(v)) return fail(ErrorCode::kInvalidInput, "mesh vertex is not finite");
  }
  const auto count = static_cast<long long>(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      if (f[k] < 0 || f[k] >= count) {
        return fail(ErrorCode::kInvalidInput, "mesh face index out of range");
      }
    }
  }
  if (mesh.faces.size() > 0xffffffffu) {
    return fail(ErrorCode::kInvalidInput, "mesh has more than 2^32 - 1 triangles");
  }
  auto impl = std::make_unique<Impl>();
  impl->mesh = std::move(mesh);
  if (impl->mesh.faces.size() > kBvhThreshold) impl->bvh = MeshBvh::build(impl->mesh);
  return MeshIntersector(std::move(impl));
}

std::optional<Hit> MeshIntersector::intersect(const Ray& ray, RayRange range) const {
  if (!usable(ray, range)) return std::nullopt;
  const TriangleMesh& m = impl_->mesh;
  if (impl_->bvh) return impl_->bvh->intersect(m, ray, range);
  std::optional<Hit> best;
  for (std::size_t i = 0; i < m.faces.size(); ++i) {
    const Eigen::Vector3i& f = m.faces[i];
    if (auto hit =
            intersectTriangle(ray, m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]], range)) {
      hit->primitive = static_cast<std::uint32_t>(i);
      range.t_max = hit->t;
      best = hit;
    }
  }
  return best;
}

bool MeshIntersector::usesBvh() const {
  return impl_->bvh.has_value();
}

const TriangleMesh& MeshIntersector::mesh() const {
  return impl_->mesh;
}

}  // namespace procam::geom
