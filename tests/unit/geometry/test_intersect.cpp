// Tests for pipelines/geometry/intersect: each primitive against its closed-form
// hit, and the mesh BVH against brute force and against the analytic sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/intersect.hpp"
#include "unit/geometry/icosphere.hpp"

namespace procam::geom {
namespace {

constexpr double kTol = 1e-12;  // closed-form cases: only rounding separates code and truth

Ray ray(const Vec3& o, const Vec3& d) {
  return Ray{o, d.normalized()};
}

void expectFacing(const Hit& hit, const Ray& r) {
  EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-14);
  EXPECT_LE(hit.normal.dot(r.dir), 0.0);
}

TEST(IntersectPlane, ObliqueRayHitsAtClosedFormDistance) {
  const Plane plane{Vec3(0, 0, 1), -2};  // z = 2
  const Ray r = ray(Vec3(1, 1, 0), Vec3(1, 0, 1));
  const auto hit = intersectPlane(r, plane);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2 * std::sqrt(2.0), kTol);
  EXPECT_TRUE(hit->point.isApprox(Vec3(3, 1, 2), kTol));
  EXPECT_TRUE(hit->normal.isApprox(Vec3(0, 0, -1), kTol));  // faces the incoming ray
  expectFacing(*hit, r);
}

TEST(IntersectPlane, ParallelBehindAndOutOfRangeMiss) {
  const Plane plane{Vec3(0, 0, 1), 0};
  EXPECT_FALSE(intersectPlane(ray(Vec3(0, 0, 1), Vec3(1, 0, 0)), plane));
  EXPECT_FALSE(intersectPlane(ray(Vec3(0, 0, 0), Vec3(1, 0, 0)), plane));  // lies in the plane
  EXPECT_FALSE(intersectPlane(ray(Vec3(0, 0, 1), Vec3(0, 0, 1)), plane));
  EXPECT_FALSE(intersectPlane(ray(Vec3(0, 0, 1), Vec3(0, 0, -1)), plane, {0.0, 0.5}));
  EXPECT_TRUE(intersectPlane(ray(Vec3(0, 0, 1), Vec3(0, 0, -1)), plane, {0.5, 1.5}));
  EXPECT_FALSE(intersectPlane(Ray{Vec3(0, 0, NAN), Vec3(0, 0, -1)}, plane));
}

TEST(IntersectRectangle, InsideHitsOutsideMissesFromBothSides) {
  const Rectangle rect{Vec3(1, 2, 3), Vec3(2, 0, 0),
                       Vec3(0, 0, 1)};  // y = 2, x in [1,3], z in [3,4]
  const Ray front = ray(Vec3(2, 0, 3.5), Vec3(0, 1, 0));
  const auto hit = intersectRectangle(front, rect);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2, kTol);
  EXPECT_TRUE(hit->normal.isApprox(Vec3(0, -1, 0), kTol));
  const Ray back = ray(Vec3(2, 5, 3.5), Vec3(0, -1, 0));
  const auto hit_back = intersectRectangle(back, rect);
  ASSERT_TRUE(hit_back);
  EXPECT_NEAR(hit_back->t, 3, kTol);
  EXPECT_TRUE(hit_back->normal.isApprox(Vec3(0, 1, 0), kTol));
  EXPECT_FALSE(intersectRectangle(ray(Vec3(3.01, 0, 3.5), Vec3(0, 1, 0)), rect));
  EXPECT_FALSE(intersectRectangle(ray(Vec3(2, 0, 2.99), Vec3(0, 1, 0)), rect));
  EXPECT_FALSE(intersectRectangle(ray(Vec3(2, 2, 3.5), Vec3(1, 0, 0)), rect));  // in its plane
}

TEST(IntersectBox, RotatedBoxFromOutsideAndInside) {
  const double a = 0.3;
  Box box;
  box.center = Vec3(1, -2, 5);
  box.half = Vec3(1, 2, 3);
  box.axes = Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix();
  // Along the box's own x axis from 10 units away: enters through the -x face.
  const Vec3 ax = box.axes.col(0);
  const Ray outside = ray(box.center - 10 * ax, ax);
  const auto hit = intersectBox(outside, box);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 9, kTol);
  EXPECT_TRUE(hit->normal.isApprox(-ax, kTol));
  EXPECT_EQ(hit->primitive, 0u);
  // From the centre along the box's z axis: exits through +z at the half extent.
  const Ray inside = ray(box.center, box.axes.col(2));
  const auto exit = intersectBox(inside, box);
  ASSERT_TRUE(exit);
  EXPECT_NEAR(exit->t, 3, kTol);
  EXPECT_TRUE(exit->normal.isApprox(-box.axes.col(2), kTol));  // against the ray
  EXPECT_EQ(exit->primitive, 5u);
  expectFacing(*exit, inside);
  // Passing beside the box.
  EXPECT_FALSE(intersectBox(ray(box.center - 10 * ax + 2.01 * box.axes.col(1), ax), box));
}

TEST(IntersectBox, AxisAlignedRaysWithZeroComponentsAreFinite) {
  const Box box;  // unit half extents at the origin
  const auto hit = intersectBox(ray(Vec3(0.5, 0.5, -4), Vec3(0, 0, 1)), box);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 3, kTol);
  EXPECT_TRUE(hit->point.isApprox(Vec3(0.5, 0.5, -1), kTol));
  // Sliding exactly along a face plane: either a finite hit on that face or a miss.
  const auto graze = intersectBox(ray(Vec3(1, 0, -4), Vec3(0, 0, 1)), box);
  if (graze) {
    EXPECT_TRUE(graze->point.allFinite());
    EXPECT_NEAR(graze->t, 3, kTol);
  }
  EXPECT_FALSE(intersectBox(ray(Vec3(1.0001, 0, -4), Vec3(0, 0, 1)), box));
}

TEST(IntersectCylinder, FromOutsideHitsNearWall) {
  const Cylinder cyl{Vec3(0, 0, 0), Vec3(0, 0, 1), 2, 3};
  const Ray r = ray(Vec3(10, 0.5, 1), Vec3(-1, 0, 0));
  const auto hit = intersectCylinder(r, cyl);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 10 - std::sqrt(4 - 0.25), kTol);
  EXPECT_TRUE(hit->normal.isApprox(Vec3(std::sqrt(3.75), 0.5, 0) / 2, kTol));
  expectFacing(*hit, r);
}

TEST(IntersectCylinder, FromInsideHitsWallWithInwardNormal) {
  const Cylinder cyl{Vec3(1, 1, 1), Vec3(1, 1, 1).normalized(), 0.5, 4};
  const Vec3 a = cyl.axis;
  const Vec3 perp = a.cross(Vec3::UnitX()).normalized();
  const Ray r = ray(cyl.base + 2 * a, perp);
  const auto hit = intersectCylinder(r, cyl);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 0.5, kTol);
  EXPECT_TRUE(hit->normal.isApprox(-perp, kTol));
}

TEST(IntersectCylinder, OpenEndsHeightLimitsAndParallelRays) {
  const Cylinder cyl{Vec3(0, 0, 0), Vec3(0, 0, 1), 1, 2};
  // Down through the open top at 45°: meets the inner wall at radius 1 after
  // travelling 1.5 horizontally; the near wall point lies above the cylinder.
  const Ray r = ray(Vec3(-0.5, 0, 3), Vec3(1, 0, -1));
  const auto hit = intersectCylinder(r, cyl);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 1.5 * std::sqrt(2.0), kTol);
  EXPECT_TRUE(hit->point.isApprox(Vec3(1, 0, 1.5), kTol));
  EXPECT_TRUE(hit->normal.isApprox(Vec3(-1, 0, 0), kTol));
  EXPECT_FALSE(intersectCylinder(ray(Vec3(5, 0, 2.5), Vec3(-1, 0, 0)), cyl));  // above
  EXPECT_FALSE(intersectCylinder(ray(Vec3(0.5, 0, -1), Vec3(0, 0, 1)), cyl));  // along axis
  EXPECT_FALSE(intersectCylinder(ray(Vec3(1, 0, -1), Vec3(0, 0, 1)), cyl));    // on the wall
}

TEST(IntersectSphere, OutsideInsideAndTangent) {
  const Sphere s{Vec3(1, 2, 3), 2};
  const auto out = intersectSphere(ray(Vec3(1, 2, 13), Vec3(0, 0, -1)), s);
  ASSERT_TRUE(out);
  EXPECT_NEAR(out->t, 8, kTol);
  EXPECT_TRUE(out->normal.isApprox(Vec3(0, 0, 1), kTol));
  const auto in = intersectSphere(ray(Vec3(1, 2, 3), Vec3(1, 0, 0)), s);
  ASSERT_TRUE(in);
  EXPECT_NEAR(in->t, 2, kTol);
  EXPECT_TRUE(in->normal.isApprox(Vec3(-1, 0, 0), kTol));
  EXPECT_FALSE(intersectSphere(ray(Vec3(3.0001, 2, 13), Vec3(0, 0, -1)), s));
}

TEST(IntersectSphere, FarAwayOriginKeepsFullPrecision) {
  // At 1e8 radii the textbook discriminant b^2 - c cancels completely (both ~1e16);
  // the closest-approach form keeps t to rounding of 1e8 (~1e-8).
  const double D = 1e8;
  const Sphere s{Vec3::Zero(), 1};
  const auto hit = intersectSphere(ray(Vec3(0.6, 0, D), Vec3(0, 0, -1)), s);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, D - 0.8, 1e-7);
  EXPECT_NEAR(hit->point.norm(), 1.0, 1e-7);
}

TEST(IntersectSphere, DomeCapRejectsTheCutPart) {
  Sphere dome{Vec3::Zero(), 5, Vec3::UnitZ(), 0};  // upper half
  const auto up = intersectSphere(ray(Vec3(0, 0, 1), Vec3(0, 0, 1)), dome);
  ASSERT_TRUE(up);
  EXPECT_NEAR(up->t, 4, kTol);
  EXPECT_TRUE(up->normal.isApprox(Vec3(0, 0, -1), kTol));
  EXPECT_FALSE(intersectSphere(ray(Vec3(0, 0, 1), Vec3(0, 0, -1)), dome));
  // From below the dome, upward from outside: the lower half is absent, so the
  // first surface is the dome's inside at z = +5.
  const auto from_below = intersectSphere(ray(Vec3(0, 0, -20), Vec3(0, 0, 1)), dome);
  ASSERT_TRUE(from_below);
  EXPECT_NEAR(from_below->t, 25, kTol);
}

TEST(IntersectTriangle, BarycentricPointTwoSided) {
  const Vec3 a(0, 0, 1), b(2, 0, 1), c(0, 2, 1);
  const Vec3 target = 0.2 * a + 0.3 * b + 0.5 * c;
  const Ray down = ray(target + Vec3(0, 0, 4), Vec3(0, 0, -1));
  const auto hit = intersectTriangle(down, a, b, c);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4, kTol);
  EXPECT_TRUE(hit->point.isApprox(target, kTol));
  EXPECT_TRUE(hit->normal.isApprox(Vec3(0, 0, 1), kTol));
  const auto up = intersectTriangle(ray(target - Vec3(0, 0, 3), Vec3(0, 0, 1)), a, b, c);
  ASSERT_TRUE(up);
  EXPECT_NEAR(up->t, 3, kTol);
  EXPECT_TRUE(up->normal.isApprox(Vec3(0, 0, -1), kTol));
}

TEST(IntersectTriangle, OutsideParallelAndDegenerateMiss) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_FALSE(intersectTriangle(ray(Vec3(0.6, 0.6, 1), Vec3(0, 0, -1)), a, b, c));
  EXPECT_FALSE(intersectTriangle(ray(Vec3(-1, 0.2, 0), Vec3(1, 0, 0)), a, b, c));  // in-plane
  EXPECT_FALSE(intersectTriangle(ray(Vec3(0.1, 0, 1), Vec3(0, 0, -1)), a, b, 2 * b));
  EXPECT_FALSE(intersectTriangle(ray(Vec3(0.1, 0.1, 1), Vec3(0, 0, -1)), a, a, a));
}

TEST(MeshIntersector, RejectsBadMeshes) {
  TriangleMesh nan_vertex = test::icosphere(Vec3::Zero(), 1, 0);
  nan_vertex.vertices[3].y() = NAN;
  auto built = MeshIntersector::build(nan_vertex);
  ASSERT_FALSE(built);
  EXPECT_EQ(built.error().code, ErrorCode::kInvalidInput);
  TriangleMesh bad_index = test::icosphere(Vec3::Zero(), 1, 0);
  bad_index.faces[7][2] = static_cast<int>(bad_index.vertices.size());
  built = MeshIntersector::build(bad_index);
  ASSERT_FALSE(built);
  EXPECT_EQ(built.error().code, ErrorCode::kInvalidInput);
  bad_index.faces[7][2] = -1;
  EXPECT_FALSE(MeshIntersector::build(bad_index));
}

TEST(MeshIntersector, SmallCubeMatchesBoxIntersection) {
  // Unit cube as 12 triangles (brute-force path) against the analytic box.
  TriangleMesh cube;
  for (int i = 0; i < 8; ++i)
    cube.vertices.emplace_back(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& q : quads) {
    cube.faces.emplace_back(q[0], q[1], q[2]);
    cube.faces.emplace_back(q[0], q[2], q[3]);
  }
  auto mesh = MeshIntersector::build(cube);
  ASSERT_TRUE(mesh);
  EXPECT_FALSE(mesh->usesBvh());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 o = 4 * Vec3(u(rng), u(rng), u(rng)).normalized();
    const Ray r = ray(o, Vec3(u(rng), u(rng), u(rng)) * 0.9 - o);
    const auto m = mesh->intersect(r);
    const auto b = intersectBox(r, Box{});
    ASSERT_EQ(m.has_value(), b.has_value()) << i;
    if (!m) continue;
    ++hits;
    EXPECT_NEAR(m->t, b->t, 1e-12);
    EXPECT_TRUE(m->normal.isApprox(b->normal, 1e-12));
  }
  EXPECT_GT(hits, 1000);
}

// Brute-force nearest hit over all triangles, independent of MeshIntersector.
std::optional<Hit> bruteForce(const TriangleMesh& m, const Ray& r) {
  std::optional<Hit> best;
  for (std::size_t i = 0; i < m.faces.size(); ++i) {
    const auto& f = m.faces[i];
    auto h = intersectTriangle(r, m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]]);
    if (h && (!best || h->t < best->t)) best = h;
  }
  return best;
}

TEST(MeshIntersector, BvhMatchesBruteForceOnTessellatedSphere) {
  const Vec3 center(0.3, -0.2, 2);
  const double R = 1.5;
  const TriangleMesh sphere = test::icosphere(center, R, 4);  // 5120 triangles
  ASSERT_GT(sphere.faces.size(), 5000u);
  auto mesh = MeshIntersector::build(sphere);
  ASSERT_TRUE(mesh);
  ASSERT_TRUE(mesh->usesBvh());
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    Vec3 o = center + Vec3(u(rng), u(rng), u(rng)) * 4;
    Vec3 d(u(rng), u(rng), u(rng));
    if (i % 3 == 0) d = center + Vec3(u(rng), u(rng), u(rng)) - o;     // mostly hitting
    if (i % 7 == 0) d = Vec3::Unit(i % 3) * (i % 2 ? 1 : -1);          // zero components
    if (i % 11 == 0) o = center + Vec3(u(rng), u(rng), u(rng)) * 0.5;  // from inside
    const Ray r = ray(o, d);
    const auto fast = mesh->intersect(r);
    const auto slow = bruteForce(sphere, r);
    ASSERT_EQ(fast.has_value(), slow.has_value()) << i;
    if (!fast) continue;
    ++hits;
    EXPECT_EQ(fast->t, slow->t) << i;  // the very same triangle test decides both
    EXPECT_TRUE(fast->normal.isApprox(slow->normal, 1e-15));
    expectFacing(*fast, r);
  }
  EXPECT_GT(hits, 1000);
}

TEST(MeshIntersector, TessellatedSphereAgreesWithAnalyticSphere) {
  // Every facet is a chord plane at distance sqrt(R^2 - rho^2) from the centre (rho:
  // its circumradius), so a ray from the centre meets the mesh between that distance
  // and R, and the facet normal is within asin(rho/R) of the radial direction.
  const Vec3 center(-1, 4, 0.5);
  const double R = 2;
  const TriangleMesh sphere = test::icosphere(center, R, 4);
  double rho_max = 0;
  for (const auto& f : sphere.faces) {
    const Vec3 a = sphere.vertices[f[0]], b = sphere.vertices[f[1]], c = sphere.vertices[f[2]];
    const double la = (b - c).norm(), lb = (a - c).norm(), lc = (a - b).norm();
    rho_max = std::max(rho_max, la * lb * lc / (2 * (b - a).cross(c - a).norm()));
  }
  const double h_min = std::sqrt(R * R - rho_max * rho_max);
  const double max_angle = std::asin(rho_max / R);
  auto mesh = MeshIntersector::build(sphere);
  ASSERT_TRUE(mesh);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 d = Vec3(g(rng), g(rng), g(rng)).normalized();
    const auto in = mesh->intersect(Ray{center, d});
    ASSERT_TRUE(in) << i;
    EXPECT_GE(in->t, h_min - 1e-12);
    EXPECT_LE(in->t, R + 1e-12);
    EXPECT_LE(std::acos(std::min(1.0, -in->normal.dot(d))), max_angle + 1e-9);
    // From outside towards the centre: the analytic sphere is hit first.
    const Ray r{center + 10 * d, -d};
    const auto out = mesh->intersect(r);
    const auto exact = intersectSphere(r, Sphere{center, R});
    ASSERT_TRUE(out && exact);
    EXPECT_NEAR(exact->t, 10 - R, 1e-12);
    EXPECT_GE(out->t, exact->t - 1e-12);
    EXPECT_LE(out->t, 10 - h_min + 1e-12);
  }
  EXPECT_LT(R - h_min, 0.01);  // the bound itself is tight enough to mean something
}

TEST(MeshIntersector, RaysAlongAnInnerEdgeHitOneOfItsTriangles) {
  // Two triangles of a curved wall sharing the diagonal a-c, seen from a projector: rays
  // aimed at points of the diagonal must not slip between them by rounding.
  TriangleMesh quad;
  quad.vertices = {Vec3(-0.71, 2.31, 1.07), Vec3(-0.63, 2.35, 1.09), Vec3(-0.62, 2.36, 1.17),
                   Vec3(-0.70, 2.32, 1.15)};
  quad.faces = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)};
  auto mesh = MeshIntersector::build(quad);
  ASSERT_TRUE(mesh);
  const Vec3 origin(-0.31, -0.25, 1.29);
  int missed = 0;
  for (int i = 1; i < 10000; ++i) {
    const Vec3 on_edge = quad.vertices[0] + (i / 10000.0) * (quad.vertices[2] - quad.vertices[0]);
    if (!mesh->intersect(Ray{origin, (on_edge - origin).normalized()})) ++missed;
  }
  EXPECT_EQ(missed, 0);
}

TEST(MeshIntersector, FlatGridWithAxisAlignedAndGrazingRays) {
  // Zero-thickness BVH nodes (all z = 0) with rays whose direction has zero components.
  const TriangleMesh grid = test::flatGrid(60, 6.0);  // 7200 triangles
  auto mesh = MeshIntersector::build(grid);
  ASSERT_TRUE(mesh);
  ASSERT_TRUE(mesh->usesBvh());
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 6);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p(u(rng), u(rng), 0);
    const auto down = mesh->intersect(Ray{p + Vec3(0, 0, 2.5), Vec3(0, 0, -1)});
    ASSERT_TRUE(down) << i;
    EXPECT_NEAR(down->t, 2.5, 1e-14);
    EXPECT_TRUE(down->normal.isApprox(Vec3(0, 0, 1), 1e-15));
    const auto up = mesh->intersect(Ray{p - Vec3(0, 0, 1), Vec3(0, 0, 1)});
    ASSERT_TRUE(up) << i;
    EXPECT_NEAR(up->t, 1.0, 1e-14);
    EXPECT_TRUE(up->normal.isApprox(Vec3(0, 0, -1), 1e-15));
    // Sliding inside the plane: parallel to every triangle, reported as a miss.
    EXPECT_FALSE(mesh->intersect(Ray{Vec3(-1, p.y(), 0), Vec3(1, 0, 0)}));
    // Out of range: the grid lies beyond t_max.
    EXPECT_FALSE(mesh->intersect(Ray{p + Vec3(0, 0, 2.5), Vec3(0, 0, -1)}, {1e-9, 2.4}));
  }
}

}  // namespace
}  // namespace procam::geom
