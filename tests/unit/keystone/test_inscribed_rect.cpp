#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "keystone/inscribed_rect.hpp"

namespace procam::keystone {
namespace {

// Oracle independent of the LP: for a fixed centre the largest half height is the
// minimum over edges (CCW polygon) of the distance budget at the worst corner.
double maxHalfHeightAt(const std::vector<Vec2>& poly, double aspect, const Vec2& c) {
  double h = 1e300;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 e = poly[(i + 1) % poly.size()] - poly[i];
    const Vec2 n = Vec2(e.y(), -e.x()).normalized();
    h = std::min(h, (n.dot(poly[i]) - n.dot(c)) / (aspect * std::abs(n.x()) + std::abs(n.y())));
  }
  return h;
}

bool inside(const std::vector<Vec2>& poly, const AxisRect& r, double tol) {
  for (int sx : {-1, 1})
    for (int sy : {-1, 1}) {
      const Vec2 p = r.centre + Vec2(sx * r.half_width, sy * r.half_height);
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Vec2 e = poly[(i + 1) % poly.size()] - poly[i];
        if (e.x() * (p.y() - poly[i].y()) - e.y() * (p.x() - poly[i].x()) < -tol) return false;
      }
    }
  return true;
}

TEST(InscribedRect, TrapezoidClosedForm) {
  // Bottom y = 0 (|x| <= 1), top y = 1 (|x| <= 2): half width 1 + y. For aspect a >= 2
  // the rectangle touches the top and both slanted sides: a h = 1 + (1 - 2h).
  const std::vector<Vec2> poly = {{-1, 0}, {1, 0}, {2, 1}, {-2, 1}};
  for (double a : {2.0, 3.0, 16.0 / 9.0 * 2, 5.0}) {
    auto r = largestInscribedRect(poly, a);
    ASSERT_TRUE(r);
    const double h = 2 / (a + 2);
    EXPECT_NEAR(r->half_height, h, 1e-12);
    EXPECT_NEAR(r->half_width, a * h, 1e-12);
    EXPECT_NEAR(r->centre.x(), 0, 1e-12);
    EXPECT_NEAR(r->centre.y(), 1 - h, 1e-12);
  }
}

TEST(InscribedRect, TiesAreResolvedByTheAnchor) {
  // A 4 x 2 box and a square: the centre can slide along x in [-1, 1].
  const std::vector<Vec2> box = {{-2, -1}, {2, -1}, {2, 1}, {-2, 1}};
  auto centred = largestInscribedRect(box, 1.0);
  ASSERT_TRUE(centred);
  EXPECT_NEAR(centred->half_height, 1, 1e-12);
  EXPECT_NEAR(centred->centre.norm(), 0, 1e-12);
  InscribeOptions keep{Anchor::kKeepPrevious, 1.0, Vec2(3, 0.4)};
  auto kept = largestInscribedRect(box, 1.0, keep);
  ASSERT_TRUE(kept);
  EXPECT_NEAR((kept->centre - Vec2(1, 0)).norm(), 0, 1e-12);
}

TEST(InscribedRect, ZoomAndAnchors) {
  const std::vector<Vec2> square = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  InscribeOptions o;
  o.zoom = 0.5;
  auto c = largestInscribedRect(square, 1.0, o);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->half_height, 0.5, 1e-12);
  EXPECT_NEAR(c->centre.norm(), 0, 1e-12);
  o.anchor = Anchor::kTop;
  auto t = largestInscribedRect(square, 1.0, o);
  ASSERT_TRUE(t);
  EXPECT_NEAR((t->centre - Vec2(0, 0.5)).norm(), 0, 1e-12);
  o.anchor = Anchor::kKeepPrevious;
  o.previous_centre = Vec2(0.9, -0.9);
  auto k = largestInscribedRect(square, 1.0, o);
  ASSERT_TRUE(k);
  EXPECT_NEAR((k->centre - Vec2(0.5, -0.5)).norm(), 0, 1e-12);
  o.previous_centre = Vec2(0.2, -0.1);  // already feasible: stays
  k = largestInscribedRect(square, 1.0, o);
  ASSERT_TRUE(k);
  EXPECT_NEAR((k->centre - Vec2(0.2, -0.1)).norm(), 0, 1e-12);
}

TEST(InscribedRect, RandomConvexPolygonsAreOptimalAgainstAGridOracle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 40; ++trial) {
    // Random convex polygon: sorted angles on a jittered ellipse, in either winding.
    const int n = 3 + trial % 6;
    std::vector<double> ang;
    for (int i = 0; i < n; ++i) ang.push_back(2 * M_PI * (i + 0.8 * u(rng)) / n);
    std::vector<Vec2> poly;
    const double ax = 1 + 3 * u(rng), ay = 1 + 3 * u(rng);
    for (double a : ang) poly.emplace_back(5 + ax * std::cos(a), -3 + ay * std::sin(a));
    const double aspect = 0.3 + 2.5 * u(rng);
    std::vector<Vec2> reversed(poly.rbegin(), poly.rend());
    auto r = largestInscribedRect(trial % 2 ? poly : reversed, aspect);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_TRUE(inside(poly, *r, 1e-9));
    EXPECT_NEAR(r->half_width, aspect * r->half_height, 1e-12);
    EXPECT_NEAR(maxHalfHeightAt(poly, aspect, r->centre), r->half_height, 1e-9);
    // No grid centre admits a larger rectangle.
    double best = 0;
    for (int i = 0; i <= 200; ++i)
      for (int j = 0; j <= 200; ++j) {
        const Vec2 c(5 - ax + 2 * ax * i / 200.0, -3 - ay + 2 * ay * j / 200.0);
        best = std::max(best, maxHalfHeightAt(poly, aspect, c));
      }
    EXPECT_GE(r->half_height, best - 1e-12);
  }
}

TEST(InscribedRect, TypedErrors) {
  const std::vector<Vec2> square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const std::vector<Vec2> dart = {{0, 0}, {2, 1}, {0, 2}, {1, 1}};
  const std::vector<Vec2> line = {{0, 0}, {1, 1}, {2, 2}};
  const std::vector<Vec2> nan = {{0, 0}, {1, NAN}, {0, 1}};
  EXPECT_EQ(largestInscribedRect(dart, 1).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(largestInscribedRect(line, 1).error().code, ErrorCode::kDegenerate);
  EXPECT_EQ(largestInscribedRect(nan, 1).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(largestInscribedRect(square, 0).error().code, ErrorCode::kInvalidInput);
  EXPECT_EQ(largestInscribedRect(square, 1, {Anchor::kCentre, 1.5, {}}).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(
      largestInscribedRect(std::vector<Vec2>(square.begin(), square.begin() + 2), 1).error().code,
      ErrorCode::kInvalidInput);
}

}  // namespace
}  // namespace procam::keystone
