// Stress: ray intersections. Rays are aimed at known surface points (closed-form
// truth), at points known to be off the surface, along grazing and parallel
// directions, with 1e4 offsets, degenerate primitives and NaN/Inf. A hit must be
// finite, on the surface and at the aimed point within rounding; a miss must be
// a true miss; ambiguous grazing cases may go either way but never return garbage.
//
// Tolerance of an aimed hit: rounding of coordinates of size S gives a hit-point
// error ~ eps * S / cos(incidence); we allow 1e3 times that (cos >= 1e-3 here).
#include <gtest/gtest.h>

#include "geometry/intersect.hpp"
#include "stress/stress_random.hpp"
#include "unit/geometry/icosphere.hpp"

namespace procam::geom {
namespace {

using stress::kEps;
using stress::Rng;

// Structural checks every returned hit must pass.
void expectSane(const std::optional<Hit>& hit, const Ray& ray, const RayRange& range = {}) {
  if (!hit) return;
  ASSERT_TRUE(std::isfinite(hit->t) && hit->point.allFinite() && hit->normal.allFinite());
  EXPECT_GT(hit->t, range.t_min);
  EXPECT_LT(hit->t, range.t_max);
  EXPECT_NEAR(hit->normal.norm(), 1.0, 1e-12);
  EXPECT_LE(hit->normal.dot(ray.dir), 1e-12);
  EXPECT_LE((hit->point - ray.at(hit->t)).norm(), 4 * kEps * (ray.origin.norm() + hit->t));
}

// A ray from `origin` through `target`.
Ray aim(const Vec3& origin, const Vec3& target) {
  return Ray{origin, (target - origin).normalized()};
}

// A direction making angle acos(c) with -n, c in [1e-3, 1] (from the side n points to).
Vec3 incoming(Rng& rng, const Vec3& n) {
  const double c = rng.chance(0.2) ? rng.logUniform(-3, 0) : rng.uniform(0.05, 1);
  const Vec3 perp = n.cross(rng.unit()).normalized();
  return (-c * n + std::sqrt(1 - c * c) * perp).normalized();
}

double tolAt(const Ray& ray, const Vec3& p, const Vec3& n, double size) {
  const double cosine = std::abs(n.dot(ray.dir));
  return 1e3 * kEps * (ray.origin.norm() + p.norm() + size) / cosine;
}

TEST(StressIntersect, Planes) {
  Rng rng(11);
  const long cases = 8000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const Vec3 n = rng.unit();
    const Vec3 p = rng.offset() + rng.inCube(10);
    const Plane plane{n, -n.dot(p)};
    const double h = rng.logUniform(-2, 3);
    const Vec3 in = incoming(rng, n);
    const Ray r{p - h * in, in};
    const int kind = static_cast<int>(i % 4);
    if (kind == 0) {  // aimed hit, also with the range just around it
      const auto hit = intersectPlane(r, plane);
      ASSERT_TRUE(hit);
      expectSane(hit, r);
      EXPECT_LE((hit->point - p).norm(), tolAt(r, p, n, h));
      EXPECT_FALSE(intersectPlane(r, plane, {1e-9, h * 0.999}));
      EXPECT_FALSE(intersectPlane(r, plane, {h * 1.001, 1e300}));
    } else if (kind == 1) {  // pointing away
      EXPECT_FALSE(intersectPlane(Ray{r.origin, -r.dir}, plane));
    } else if (kind == 2) {  // parallel up to rounding: a miss or a far hit still on the plane
      const Ray par{r.origin, n.cross(rng.unit()).normalized()};
      const auto hit = intersectPlane(par, plane);
      expectSane(hit, par);
      if (hit) {
        EXPECT_LE(std::abs(plane.signedDistance(hit->point)),
                  16 * kEps * hit->point.norm() + 1e3 * kEps * p.norm());
      }
    } else {  // non-finite ray or plane
      Ray bad = r;
      Plane bad_plane = plane;
      if (rng.chance(0.5)) {
        (rng.chance(0.5) ? bad.origin : bad.dir)[rng.integer(0, 2)] = rng.bad();
      } else {
        bad_plane.d = rng.bad();
      }
      EXPECT_FALSE(intersectPlane(bad, bad_plane));
    }
  }
  stress::report("ray-plane", cases);
}

TEST(StressIntersect, Rectangles) {
  Rng rng(12);
  const long cases = 5000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const Mat3 R = rng.rotation();
    const Rectangle rect{rng.offset(), R.col(0) * rng.logUniform(-1, 2),
                         R.col(1) * rng.logUniform(-1, 2)};
    const Vec3 n = R.col(2) * (rng.chance(0.5) ? 1 : -1);
    const bool inside = i % 2 == 0;
    // Target at a distance `margin` (fraction of the side) inside or outside an edge.
    const double margin = rng.logUniform(-10, -0.4);
    const bool along_u = rng.chance(0.5);
    double a = rng.uniform(0, 1), b = rng.uniform(0, 1);
    double& edge = along_u ? a : b;
    edge = rng.chance(0.5) ? (inside ? margin : -margin) : (inside ? 1 - margin : 1 + margin);
    const Vec3 p = rect.origin + a * rect.u + b * rect.v;
    const Ray r = aim(p - rng.logUniform(-1, 3) * incoming(rng, n), p);
    const auto hit = intersectRectangle(r, rect);
    expectSane(hit, r);
    const double tol = tolAt(r, p, n, rect.u.norm() + rect.v.norm());
    if (margin * (along_u ? rect.u : rect.v).norm() <= tol)
      continue;  // within rounding of the edge
    ASSERT_EQ(hit.has_value(), inside);
    if (hit) {
      EXPECT_LE((hit->point - p).norm(), tol);
    }
  }
  stress::report("ray-rectangle", cases);
}

TEST(StressIntersect, Boxes) {
  Rng rng(13);
  const long cases = 8000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    Box box;
    box.center = rng.offset() + rng.inCube(5);
    box.half = Vec3(rng.logUniform(-1, 1), rng.logUniform(-1, 1), rng.logUniform(-1, 1));
    box.axes = i % 5 == 0 ? Mat3::Identity() : rng.rotation();
    const int axis = rng.integer(0, 2);
    const double side = rng.chance(0.5) ? 1 : -1;
    const Vec3 n = side * box.axes.col(axis);  // outward normal of the aimed face
    Vec3 local(rng.uniform(-0.99, 0.99), rng.uniform(-0.99, 0.99), rng.uniform(-0.99, 0.99));
    local[axis] = side;
    const Vec3 p = box.center + box.axes * local.cwiseProduct(box.half);
    const double size = box.half.norm();
    const int kind = static_cast<int>(i % 4);
    if (kind == 0 || kind == 1) {
      Ray r;
      if (kind == 0) {  // from outside the face plane: that face is the first hit
        r = aim(p - rng.logUniform(-1, 3) * incoming(rng, n), p);
        if (i % 5 == 0 && rng.chance(0.5))
          r = Ray{p + rng.logUniform(-1, 3) * n, -n};  // axis-aligned
      } else {                                         // from inside: exits through the aimed face
        const Vec3 o = box.center + box.axes * (0.9 * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1),
                                                           rng.uniform(-1, 1)))
                                                   .cwiseProduct(box.half);
        r = aim(o, p);
        if (std::abs(r.dir.dot(n)) < 1e-3) continue;
      }
      const auto hit = intersectBox(r, box);
      ASSERT_TRUE(hit);
      expectSane(hit, r);
      EXPECT_LE((hit->point - p).norm(), tolAt(r, p, n, size));
      EXPECT_LE((hit->normal + (kind == 0 ? -1 : 1) * n).norm(), 1e-12);
    } else if (kind == 2) {  // sliding along a face plane, inside or outside the face
      const Vec3 along = box.axes.col((axis + 1) % 3);
      const Ray r{p - 3 * size * along + (rng.chance(0.5) ? 0 : 1e-3) * n, along};
      const auto hit = intersectBox(r, box);
      expectSane(hit, r);
      if (hit) {
        const Vec3 q = box.axes.transpose() * (hit->point - box.center);
        EXPECT_LE((q.cwiseAbs() - box.half).maxCoeff(), 1e3 * kEps * (size + box.center.norm()));
      }
    } else {  // non-finite or zero direction
      Ray r = aim(p + n, p);
      if (rng.chance(0.3))
        r.dir = Vec3::Zero();
      else
        (rng.chance(0.5) ? r.origin : r.dir)[rng.integer(0, 2)] = rng.bad();
      EXPECT_FALSE(intersectBox(r, box));
    }
  }
  stress::report("ray-box", cases);
}

TEST(StressIntersect, Cylinders) {
  Rng rng(14);
  const long cases = 8000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    Cylinder cyl{rng.offset() + rng.inCube(5), rng.unit(), rng.logUniform(-1, 1),
                 rng.logUniform(-1, 1)};
    const Vec3 radial = cyl.axis.unitOrthogonal();
    const Vec3 n = Eigen::AngleAxisd(rng.uniform(0, 2 * M_PI), cyl.axis) * radial;
    const double s = rng.uniform(0.01, 0.99) * cyl.height;
    const Vec3 p = cyl.base + s * cyl.axis + cyl.radius * n;
    const double size = cyl.radius + cyl.height;
    const int kind = static_cast<int>(i % 4);
    if (kind == 0 || kind == 1) {
      Ray r;
      if (kind == 0) {  // outside the tangent plane at p: p is the first hit
        r = aim(p - rng.logUniform(-1, 3) * incoming(rng, n), p);
      } else {  // from inside: the wall is left exactly once, at p
        const Vec3 o = cyl.base + rng.uniform(0, 1) * cyl.height * cyl.axis +
                       rng.uniform(0, 0.9) * cyl.radius *
                           (Eigen::AngleAxisd(rng.uniform(0, 6.28), cyl.axis) * radial);
        r = aim(o, p);
        if (std::abs(r.dir.dot(n)) < 1e-3) continue;
      }
      const auto hit = intersectCylinder(r, cyl);
      ASSERT_TRUE(hit);
      expectSane(hit, r);
      EXPECT_LE((hit->point - p).norm(), tolAt(r, p, n, size));
      EXPECT_LE((hit->normal + (kind == 0 ? -1 : 1) * n).norm(),
                1e-9 + tolAt(r, p, n, size) / cyl.radius);
    } else if (kind == 2) {  // tangent (grazing) rays and rays parallel to the axis
      const Vec3 tangent = rng.chance(0.5) ? cyl.axis : n.cross(cyl.axis);
      const Ray r{p - 2 * size * tangent, tangent};
      const auto hit = intersectCylinder(r, cyl);
      expectSane(hit, r);
      if (hit) {
        const Vec3 rel = hit->point - cyl.base;
        const double along = rel.dot(cyl.axis);
        EXPECT_NEAR((rel - along * cyl.axis).norm(), cyl.radius, 1e6 * kEps * (size + p.norm()));
      }
    } else {  // degenerate cylinders and non-finite rays
      const Ray r = aim(p + n, p);
      Cylinder bad = cyl;
      const int k = rng.integer(0, 3);
      if (k == 0) bad.radius = 0;
      if (k == 1) bad.axis = Vec3::Zero();
      if (k == 2) bad.height = rng.bad();
      Ray bad_ray = r;
      if (k == 3) bad_ray.origin[rng.integer(0, 2)] = rng.bad();
      EXPECT_FALSE(intersectCylinder(bad_ray, bad));
    }
  }
  stress::report("ray-cylinder", cases);
}

TEST(StressIntersect, SpheresAndDomes) {
  Rng rng(15);
  const long cases = 8000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    Sphere sphere{rng.offset() + rng.inCube(5), rng.logUniform(-1, 2)};
    const bool dome = i % 3 == 0;
    if (dome) {
      sphere.cap_axis = rng.unit();
      sphere.cap_min = rng.uniform(-0.5, 0.5) * sphere.radius;
    }
    const Vec3 n = rng.unit();
    const Vec3 p = sphere.center + sphere.radius * n;
    const bool on_cap = n.dot(sphere.cap_axis) * sphere.radius >= sphere.cap_min;
    const int kind = static_cast<int>(i % 4);
    if (kind == 0 && !dome) {  // from outside, p faces the origin: p is the first hit
      const Ray r = aim(p - rng.logUniform(-2, 6) * sphere.radius * incoming(rng, n), p);
      const auto hit = intersectSphere(r, sphere);
      ASSERT_TRUE(hit);
      expectSane(hit, r);
      EXPECT_LE((hit->point - p).norm(), tolAt(r, p, n, sphere.radius));
      EXPECT_LE((hit->normal - n).norm(), 1e-14 + tolAt(r, p, n, sphere.radius) / sphere.radius);
    } else if (kind <= 1) {  // from inside: the sphere is left once, at p
      const Ray r = aim(sphere.center + 0.9 * sphere.radius * rng.uniform(0, 1) * rng.unit(), p);
      if (std::abs(r.dir.dot(n)) < 1e-3) continue;
      const auto hit = intersectSphere(r, sphere);
      expectSane(hit, r);
      // On a dome the exit point must be on the kept cap; cut points are misses
      // (with a margin of rounding around the cut plane).
      const double cap_dist = n.dot(sphere.cap_axis) * sphere.radius - sphere.cap_min;
      if (dome && std::abs(cap_dist) < 1e-9 * sphere.radius) continue;
      ASSERT_EQ(hit.has_value(), on_cap);
      if (hit) {
        const double tol = tolAt(r, p, n, sphere.radius);
        EXPECT_LE((hit->point - p).norm(), tol);
        EXPECT_LE((hit->normal + n).norm(), 1e-14 + tol / sphere.radius);
      }
    } else if (kind == 2) {  // tangent rays: miss or a point on the sphere
      const Vec3 tangent = n.cross(rng.unit()).normalized();
      const Ray r{p - 2 * sphere.radius * tangent + rng.uniform(-1e-9, 1e-9) * sphere.radius * n,
                  tangent};
      const auto hit = intersectSphere(r, sphere);
      expectSane(hit, r);
      if (hit) {
        EXPECT_NEAR((hit->point - sphere.center).norm(), sphere.radius,
                    1e3 * kEps * (sphere.center.norm() + sphere.radius));
      }
    } else {
      Ray r = aim(p + n, p);
      Sphere bad = sphere;
      const int k = rng.integer(0, 2);
      if (k == 0) bad.radius = rng.chance(0.5) ? 0 : rng.bad();
      if (k == 1) bad.center[rng.integer(0, 2)] = rng.bad();
      if (k == 2) r.dir = Vec3::Zero();
      EXPECT_FALSE(intersectSphere(r, bad));
    }
  }
  stress::report("ray-sphere/dome", cases);
}

// Möller–Trumbore in long double without any thresholds: the reference the
// double version is held to, with a tolerance from its conditioning.
struct ReferenceHit {
  long double t, u, v, sine, cosine;
  Vec3 point;
};

ReferenceHit reference(const Ray& r, const Vec3& a, const Vec3& b, const Vec3& c) {
  using V = Eigen::Matrix<long double, 3, 1>;
  const V A = a.cast<long double>(), O = r.origin.cast<long double>(),
          D = r.dir.cast<long double>();
  const V e1 = b.cast<long double>() - A, e2 = c.cast<long double>() - A;
  const V n = e1.cross(e2), p = D.cross(e2), s = O - A, q = s.cross(e1);
  const long double det = e1.dot(p);
  ReferenceHit ref;
  ref.sine = n.norm() / (e1.norm() * e2.norm());
  ref.cosine = std::abs(D.dot(n)) / (n.norm() * D.norm());
  ref.u = s.dot(p) / det;
  ref.v = D.dot(q) / det;
  ref.t = e2.dot(q) / det;
  ref.point = (O + ref.t * D).cast<double>();
  return ref;
}

TEST(StressIntersect, Triangles) {
  Rng rng(16);
  const long cases = 10000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const Vec3 c0 = rng.offset() + rng.inCube(5);
    const double size = rng.logUniform(-2, 2);
    Vec3 a = c0 + size * rng.unit(), b = c0 + size * rng.unit(), c = c0 + size * rng.unit();
    const int kind = static_cast<int>(i % 5);
    if (kind == 3) {  // degenerate: repeated vertex, or collinear up to a tiny width
      if (rng.chance(0.2)) {
        b = a;
      } else {
        const Vec3 e = b - a;
        c = a + rng.uniform(-2, 2) * e + rng.logUniform(-16, -5) * e.norm() * e.unitOrthogonal();
      }
    }
    const Vec3 e = (b - a).cross(c - a);
    const Vec3 n = e.norm() > 0 ? Vec3(e.normalized()) : Vec3::UnitZ();
    // Barycentric target: inside or outside, some within 1e-10 of an edge.
    Vec3 w(rng.uniform(1e-3, 1), rng.uniform(1e-3, 1), rng.uniform(1e-3, 1));
    if (kind == 1) w[rng.integer(0, 2)] = -rng.logUniform(-10, 0);
    if (kind == 2) w[rng.integer(0, 2)] = rng.logUniform(-10, -3);  // close inside an edge
    w /= w.sum();
    const Vec3 p = w[0] * a + w[1] * b + w[2] * c;
    Ray r = aim(p - rng.logUniform(-1, 3) * incoming(rng, rng.chance(0.5) ? n : Vec3(-n)), p);
    if (kind == 4) r = Ray{p - 2 * size * (b - a).normalized(), (b - a).normalized()};  // in-plane
    const auto hit = intersectTriangle(r, a, b, c);
    expectSane(hit, r);
    if (b == a) {
      EXPECT_FALSE(hit);
      continue;
    }
    const ReferenceHit ref = reference(r, a, b, c);
    if (ref.sine < 0.99e-8) {  // below the degeneracy threshold
      EXPECT_FALSE(hit) << "sine " << static_cast<double>(ref.sine);
      continue;
    }
    // Rounding of the double computation: eps relative on e1, e2, s, d and their
    // products, divided by |det| = |e1||e2| sin cos (see the derivation in the
    // file header); 1e3 safety.
    const double cond = 1.0 / static_cast<double>(ref.sine * ref.cosine);
    const double sn = (r.origin - a).norm();
    const double tol_bary = 1e3 * kEps * cond * (sn / std::min((b - a).norm(), (c - a).norm()) + 2);
    const double margin = static_cast<double>(std::min({ref.u, ref.v, 1 - ref.u - ref.v}));
    const double t_ref = static_cast<double>(ref.t);
    if (hit) {
      EXPECT_GE(margin, -tol_bary);
      // plus rounding of the point coordinates themselves
      EXPECT_LE((hit->point - ref.point).norm(),
                1e3 * kEps * cond * (sn + t_ref) + 8 * kEps * (r.origin.norm() + p.norm()));
    } else {
      const bool ambiguous = margin <= tol_bary || ref.cosine < 1e-11 || ref.sine < 1.01e-8 ||
                             t_ref <= 1e-9 * (1 + 1e3 * kEps * cond);
      EXPECT_TRUE(ambiguous) << "missed: margin " << margin << " t " << t_ref;
    }
    // Construction check, independent of the reference, where well conditioned.
    if (kind == 0 && ref.sine > 1e-3) {
      ASSERT_TRUE(hit);
      EXPECT_LE((hit->point - p).norm(), tolAt(r, p, n, size) / static_cast<double>(ref.sine));
    }
    if (kind == 1 && ref.sine > 1e-3 && w.minCoeff() < -1e-3) {
      EXPECT_FALSE(hit);
    }
  }
  stress::report("ray-triangle", cases);
}

TEST(StressIntersect, MeshBvhAgainstBruteForce) {
  // A tessellated sphere 1e4 away, with collapsed and sliver triangles mixed in:
  // the BVH must return exactly the nearest t of a scan over all triangles.
  Rng rng(17);
  const Vec3 center = 1e4 * Vec3(0.6, -0.8, 0);
  TriangleMesh mesh = test::icosphere(center, 3, 4);
  const int base = static_cast<int>(mesh.vertices.size());
  for (int k = 0; k < 400; ++k) {
    const Vec3 q = center + rng.inCube(3);
    mesh.vertices.push_back(q);
    mesh.vertices.push_back(q + (k % 2 ? Vec3::Zero() : Vec3(1e-14, 0, 0)));
    mesh.vertices.push_back(q + rng.unit() * 0.5);
    mesh.faces.emplace_back(base + 3 * k, base + 3 * k + 1, base + 3 * k + 2);
  }
  const TriangleMesh copy = mesh;
  auto bvh = MeshIntersector::build(std::move(mesh));
  ASSERT_TRUE(bvh);
  ASSERT_TRUE(bvh->usesBvh());
  const long cases = 3000;
  long hits = 0;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    Vec3 o = center + rng.inCube(i % 4 == 0 ? 2 : 8);
    Vec3 d = i % 3 == 0 ? Vec3(center + rng.inCube(2) - o) : rng.unit();
    if (i % 10 == 0) d = Vec3::Unit(rng.integer(0, 2)) * (rng.chance(0.5) ? 1 : -1);
    const Ray r{o, d.normalized()};
    const RayRange range{1e-9, rng.chance(0.2) ? rng.uniform(0, 10) : 1e300};
    const auto fast = bvh->intersect(r, range);
    std::optional<Hit> slow;
    for (const auto& f : copy.faces) {
      auto h = intersectTriangle(r, copy.vertices[f[0]], copy.vertices[f[1]], copy.vertices[f[2]],
                                 range);
      if (h && (!slow || h->t < slow->t)) slow = h;
    }
    ASSERT_EQ(fast.has_value(), slow.has_value());
    expectSane(fast, r, range);
    if (fast) {
      ++hits;
      EXPECT_EQ(fast->t, slow->t);
    }
  }
  EXPECT_GT(hits, cases / 4);
  stress::report("mesh BVH vs brute force", cases);
}

}  // namespace
}  // namespace procam::geom
