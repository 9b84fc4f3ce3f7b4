// Stress: rigid transform, triangulation, plane fit. Random and adversarial inputs
// (collinear and near-collinear sets, duplicated points, 1e4 offsets, parallel
// rays, points at infinity, NaN/Inf); every result must be finite and correct
// within a rounding-derived tolerance, or a typed error.
//
// Tolerances: exact data carry only rounding, ~eps * (coordinate magnitude), which
// the estimate amplifies by its conditioning (offset/extent, 1/sin of ray angles,
// ratio of principal extents). Each check below is C * eps * that product with
// C = 1e3..1e4: far above rounding, far below any wrong answer (errors of O(1)).
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>

#include "geometry/plane_fit.hpp"
#include "geometry/rigid.hpp"
#include "geometry/triangulate.hpp"
#include "stress/stress_random.hpp"

namespace procam::geom {
namespace {

using stress::kEps;
using stress::Rng;

// Singular values of the centred set (sqrt(n) times the rms extent along each
// principal axis).
Vec3 extents(const Points3& pts) {
  Eigen::MatrixX3d m(static_cast<Eigen::Index>(pts.size()), 3);
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = pts[i] - mean;
  return Eigen::JacobiSVD<Eigen::MatrixX3d>(m).singularValues();
}

// Ratio of the two largest principal extents (1 = isotropic, 0 = collinear).
double planarity(const Points3& pts) {
  const Vec3 s = extents(pts);
  return s[1] / s[0];
}

// Within a factor 4 of a documented collinearity threshold: the extent ratio of
// the estimator, or its floor of 256 eps |x| per point (rigid.cpp, plane_fit.cpp).
// There a typed error and an answer are both acceptable.
bool nearCollinear(const Points3& pts, double ratio) {
  const Vec3 s = extents(pts);
  double max_abs = 0;
  for (const Vec3& p : pts) max_abs = std::max(max_abs, p.cwiseAbs().maxCoeff());
  const double floor = 4 * 256 * kEps * max_abs * std::sqrt(static_cast<double>(pts.size()));
  return s[1] < 4 * ratio * s[0] || s[1] < floor;
}

Points3 cloud(Rng& rng, int n, const Vec3& center, double spread) {
  Points3 pts;
  for (int i = 0; i < n; ++i) pts.push_back(center + rng.inCube(spread));
  return pts;
}

void expectRotation(const Mat3& R) {
  ASSERT_TRUE(R.allFinite());
  EXPECT_LT((R * R.transpose() - Mat3::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

TEST(StressPrimitives, RigidTransform) {
  Rng rng(101);
  const long cases = 12000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const int kind = static_cast<int>(i % 8);
    const Vec3 offset = rng.offset();
    const double spread = rng.logUniform(-2, 3);
    const Mat3 R = rng.rotation();
    const Vec3 t = rng.offset() + rng.inCube(10);
    const bool with_scale = rng.chance(0.3);
    const double s = with_scale ? rng.logUniform(-1, 1) : 1.0;
    const int n = rng.integer(3, 30);
    Points3 from = cloud(rng, n, offset, spread);
    if (kind == 4) {  // exactly collinear (rounding stays far below the threshold)
      const Vec3 d = rng.unit();
      for (Vec3& p : from) p = offset + rng.uniform(-spread, spread) * d;
    } else if (kind == 5) {  // duplicated points: all coincide, or three distinct ones repeated
      const bool coincide = rng.chance(0.5);
      for (int k = 0; k < n; ++k) from[k] = coincide ? from[0] : from[k % 3];
    } else if (kind == 7) {  // near-collinear: width 1e-13..1e-2 of the length
      const Vec3 d = rng.unit();
      const Vec3 w = d.unitOrthogonal() * spread * rng.logUniform(-13, -2);
      for (Vec3& p : from) p = offset + rng.uniform(-spread, spread) * d + rng.uniform(-1, 1) * w;
    }
    Points3 to;
    for (const Vec3& p : from) to.push_back(s * R * p + t);
    if (kind == 6) {  // NaN/Inf anywhere
      Points3& victim = rng.chance(0.5) ? from : to;
      victim[rng.integer(0, n - 1)][rng.integer(0, 2)] = rng.bad();
    }
    const auto fit = fitRigidTransform(from, to, with_scale);
    if (kind == 6) {
      ASSERT_FALSE(fit);
      EXPECT_EQ(fit.error().code, ErrorCode::kInvalidInput);
      continue;
    }
    if (kind == 4 || (kind == 5 && (from[1] == from[0] || n < 3))) {
      ASSERT_FALSE(fit);
      EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
      continue;
    }
    if (!fit && nearCollinear(from, 1e-5)) {
      EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
      continue;
    }
    ASSERT_TRUE(fit) << fit.error().message;
    expectRotation(fit->R);
    ASSERT_TRUE(fit->t.allFinite() && std::isfinite(fit->scale) && std::isfinite(fit->rms));
    const double mag = offset.norm() + spread + t.norm();
    // Rounding of both point sets relative to their extent, amplified by the
    // squared extent ratio through the cross-covariance (see rigid.cpp).
    const double p = planarity(from);
    // Residual of the data itself: exact correspondences map onto each other up to
    // the rotation error about the long axis times the thin extent, ~eps |x| / p.
    EXPECT_LE(fit->rms, 1e4 * kEps * (s * mag + t.norm() + 1) / p);
    const double cond = (1 + (offset.norm() + t.norm() / s) / spread) / (p * p);
    EXPECT_LE((fit->R - R).norm(), 1e4 * kEps * cond);
    EXPECT_LE(std::abs(fit->scale - s), 1e4 * kEps * cond * s);
    EXPECT_LE((fit->t - t).norm(), 1e4 * kEps * cond * (s * mag + t.norm()));
  }
  // Size mismatch and too few points.
  const Points3 three = cloud(rng, 3, Vec3::Zero(), 1);
  EXPECT_EQ(fitRigidTransform(three, std::span(three).first(2)).error().code,
            ErrorCode::kInvalidInput);
  EXPECT_EQ(fitRigidTransform(std::span(three).first(2), std::span(three).first(2)).error().code,
            ErrorCode::kTooFewPoints);
  stress::report("rigid transform", cases + 2);
}

TEST(StressPrimitives, RayRayTriangulation) {
  Rng rng(202);
  const long cases = 15000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const int kind = static_cast<int>(i % 8);
    const Vec3 X = rng.offset() + rng.inCube(5);
    const double D = rng.logUniform(-1, 3);
    Ray a{X - D * rng.unit(), Vec3::Zero()};
    Ray b{X - D * rng.logUniform(-1, 1) * rng.unit(), Vec3::Zero()};
    a.dir = (X - a.origin).normalized();
    b.dir = (X - b.origin).normalized();
    const double scale = X.norm() + (a.origin - X).norm() + (b.origin - X).norm();
    if (kind == 4) {  // exactly parallel or within 1e-9 rad
      b.dir = rng.chance(0.5)
                  ? a.dir
                  : (a.dir + rng.logUniform(-16, -9) * a.dir.unitOrthogonal()).normalized();
      if (rng.chance(0.5)) b.dir = -b.dir;
      const auto r = triangulateRays(a, b);
      ASSERT_FALSE(r);
      EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
      continue;
    }
    if (kind == 5) {  // NaN/Inf or zero direction
      Ray& victim = rng.chance(0.5) ? a : b;
      if (rng.chance(0.3)) {
        victim.dir = Vec3::Zero();
      } else {
        (rng.chance(0.5) ? victim.origin : victim.dir)[rng.integer(0, 2)] = rng.bad();
      }
      const auto r = triangulateRays(a, b);
      ASSERT_FALSE(r);
      EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
      continue;
    }
    Vec3 expect = X;
    double gap = 0;
    if (kind == 6) {  // skew rays with a known common perpendicular
      const Vec3 n = rng.unit();
      gap = rng.logUniform(-3, 1);
      const Vec3 d1 = n.unitOrthogonal();
      const Vec3 d2 = Eigen::AngleAxisd(rng.uniform(0.01, 3.13), n) * d1;
      const double t1 = rng.uniform(-D, D), t2 = rng.uniform(-D, D);
      a = Ray{X - t1 * d1, d1};
      b = Ray{X + gap * n - t2 * d2, d2};
      expect = X + 0.5 * gap * n;
    } else if (kind == 7) {  // common origin: the rays meet there
      b.origin = a.origin;
      b.dir = rng.unit();
      expect = a.origin;
    }
    const double sin_angle = a.dir.cross(b.dir).norm();
    const auto r = triangulateRays(a, b);
    if (sin_angle < 1e-7 && !r) {  // the degeneracy threshold lies near here
      EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
      continue;
    }
    ASSERT_TRUE(r) << r.error().message << " sin " << sin_angle;
    ASSERT_TRUE(r->point.allFinite() && std::isfinite(r->gap));
    const double tol = 1e3 * kEps * (scale + gap) / sin_angle;
    EXPECT_LE((r->point - expect).norm(), tol);
    EXPECT_NEAR(r->gap, gap, tol);
    EXPECT_LE((a.at(r->t1) - b.at(r->t2)).norm(), gap + tol);
  }
  stress::report("ray-ray triangulation", cases);
}

Mat34 makeP(const Mat3& K, const Mat3& R, const Vec3& center) {
  Mat34 Rt;
  Rt << R, -R * center;
  return K * Rt;
}

Mat3 lookAt(const Vec3& center, const Vec3& target, Rng& rng) {
  const Vec3 z = (target - center).normalized();
  const Vec3 x = rng.unit().cross(z).normalized();
  Mat3 R;
  R << x.transpose(), z.cross(x).transpose(), z.transpose();
  return R;
}

TEST(StressPrimitives, LinearTriangulation) {
  Rng rng(303);
  const long cases = 10000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const int kind = static_cast<int>(i % 6);
    const Vec3 offset = rng.offset();
    const double Z = rng.logUniform(0, 1.3);
    const double B = Z * rng.logUniform(-2, 0);
    const Vec3 X = offset + rng.inCube(0.2 * Z);
    const Vec3 base = X - Z * rng.unit();
    const int views = rng.integer(2, 5);
    std::vector<Mat34> P;
    std::vector<Vec2> px;
    for (int v = 0; v < views; ++v) {
      Mat3 K = Mat3::Identity();
      K(0, 0) = K(1, 1) = rng.uniform(500, 4000);  // 4K-sized raw pixel coordinates
      K(0, 2) = rng.uniform(0, 3840);
      K(1, 2) = rng.uniform(0, 2160);
      Vec3 c = base + B * rng.unit();
      if (kind == 3) c = base;  // all centres coincide: a single ray
      P.push_back(makeP(K, lookAt(c, X, rng), c));
      const Vec3 x = P.back() * X.homogeneous();
      px.push_back(x.hnormalized());
    }
    if (kind == 4) {  // the point at infinity in direction d: same direction in every view
      const Vec3 d = rng.unit();
      for (int v = 0; v < views; ++v) px[v] = (P[v].leftCols<3>() * d).hnormalized();
    }
    if (kind == 5) {  // NaN/Inf in a matrix or a pixel
      if (rng.chance(0.5)) {
        P[rng.integer(0, views - 1)](rng.integer(0, 2), rng.integer(0, 3)) = rng.bad();
      } else {
        px[rng.integer(0, views - 1)][rng.integer(0, 1)] = rng.bad();
      }
    }
    const auto r = triangulateLinear(P, px);
    if (kind == 5) {
      ASSERT_FALSE(r);
      EXPECT_EQ(r.error().code, ErrorCode::kInvalidInput);
      continue;
    }
    if (kind == 3 || kind == 4) {
      ASSERT_FALSE(r) << "point " << r->transpose();
      EXPECT_EQ(r.error().code, ErrorCode::kDegenerate);
      continue;
    }
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->allFinite());
    // Rounding of pixels (~eps * 4000) acts as pixel noise, amplified by the stereo
    // depth factor Z^2 / (f B) with f >= 500; plus rounding of the offset coordinates.
    const double tol = 1e4 * kEps * (4000 * Z * Z / (500 * B) + offset.norm() * Z / B + Z);
    EXPECT_LE((*r - X).norm(), tol) << "Z " << Z << " B " << B;
  }
  stress::report("linear triangulation", cases);
}

Points3 planeSample(Rng& rng, int n, const Vec3& normal, const Vec3& center, double su, double sv) {
  const Vec3 u = normal.unitOrthogonal(), v = normal.cross(u);
  Points3 pts;
  for (int k = 0; k < n; ++k)
    pts.push_back(center + rng.uniform(-su, su) * u + rng.uniform(-sv, sv) * v);
  return pts;
}

// Angle between lines (atan2 form: acos loses everything below ~1e-8 rad).
double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

TEST(StressPrimitives, PlaneFitLeastSquares) {
  Rng rng(404);
  const long cases = 12000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const int kind = static_cast<int>(i % 7);
    const Vec3 normal = rng.unit();
    const Vec3 center = rng.offset() + rng.inCube(1);
    const double su = rng.logUniform(-2, 3);
    const double sv = su * rng.logUniform(-3, 0);
    const int n = rng.integer(3, 200);
    Points3 pts = planeSample(rng, n, normal, center, su, sv);
    double sigma = 0;
    if (kind == 1) {  // noisy
      sigma = sv * 1e-3;
      std::normal_distribution<double> g(0, sigma);
      for (Vec3& p : pts) p += g(rng.gen) * normal;
    } else if (kind == 2) {  // exactly collinear
      const Vec3 d = rng.unit();
      for (Vec3& p : pts) p = center + rng.uniform(-su, su) * d;
    } else if (kind == 3) {  // duplicates: all equal, or three distinct points repeated
      const bool coincide = rng.chance(0.5);
      for (int k = 0; k < n; ++k) pts[k] = coincide ? pts[0] : pts[k % 3];
    } else if (kind == 4) {  // NaN/Inf
      pts[rng.integer(0, n - 1)][rng.integer(0, 2)] = rng.bad();
    } else if (kind == 5) {  // too few
      pts.resize(rng.integer(0, 2));
    }
    const auto fit = fitPlane(pts);
    if (kind == 4 || kind == 5) {
      ASSERT_FALSE(fit);
      EXPECT_EQ(fit.error().code, kind == 4 ? ErrorCode::kInvalidInput : ErrorCode::kTooFewPoints);
      continue;
    }
    if (kind == 2 || (kind == 3 && pts[1] == pts[0])) {
      ASSERT_FALSE(fit);
      EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
      continue;
    }
    if (!fit && nearCollinear(pts, 1e-9)) {  // a thin random sample
      EXPECT_EQ(fit.error().code, ErrorCode::kDegenerate);
      continue;
    }
    ASSERT_TRUE(fit) << fit.error().message;
    ASSERT_TRUE(fit->plane.n.allFinite() && std::isfinite(fit->plane.d) && std::isfinite(fit->rms));
    EXPECT_NEAR(fit->plane.n.norm(), 1, 1e-14);
    // Conditioning of the sample itself: the rms extent along its second principal
    // axis (a few random points in a strip can be much thinner than the strip).
    const double extent = extents(pts)[1] / std::sqrt(static_cast<double>(pts.size()));
    const double mag = center.norm() + su;
    const double tol_angle = 1e4 * kEps * mag / extent;
    if (kind != 1) {
      EXPECT_LE(angleBetween(fit->plane.n, normal), tol_angle);
      EXPECT_LE(std::abs(fit->plane.signedDistance(center)), tol_angle * su + 1e4 * kEps * mag);
      EXPECT_LE(fit->rms, 1e4 * kEps * mag);
      continue;
    }
    // Noisy: least squares can never fit worse than the true plane ...
    double truth_ss = 0;
    for (const Vec3& p : pts) truth_ss += std::pow(normal.dot(p - center), 2);
    EXPECT_LE(fit->rms, std::sqrt(truth_ss / n) * (1 + 1e-9) + 1e4 * kEps * mag);
    // ... and, while the first-order model holds, tilts by sigma / (sqrt(n) rms extent)
    // per axis: 6 of those (2-axis chi: exceeded with probability ~1e-8).
    const double tilt = sigma / (std::sqrt(static_cast<double>(n)) * extent);
    if (tilt < 0.01) {
      EXPECT_LE(angleBetween(fit->plane.n, normal), tol_angle + 6 * tilt);
    }
  }
  stress::report("plane fit (least squares)", cases);
}

TEST(StressPrimitives, PlaneFitRansac) {
  Rng rng(505);
  const long cases = 3000;
  for (long i = 0; i < cases; ++i) {
    SCOPED_TRACE(i);
    const int kind = static_cast<int>(i % 5);
    const Vec3 normal = rng.unit();
    const Vec3 center = rng.offset();
    const double su = rng.logUniform(-1, 2);
    const int inliers = rng.integer(10, 60);
    const int outliers = rng.integer(0, inliers * 2 / 3);
    Points3 pts = planeSample(rng, inliers, normal, center, su, su * rng.logUniform(-1, 0));
    for (int k = 0; k < outliers; ++k) pts.push_back(center + rng.inCube(su));
    RansacOptions opt;
    opt.threshold = su * 1e-6;
    opt.seed = static_cast<std::uint64_t>(i);
    opt.iterations = 2000;
    if (kind == 2) {  // all points on one line (outliers too)
      const Vec3 d = rng.unit();
      for (Vec3& p : pts) p = center + rng.uniform(-su, su) * d;
    } else if (kind == 3) {
      pts[rng.integer(0, static_cast<int>(pts.size()) - 1)][rng.integer(0, 2)] = rng.bad();
    } else if (kind == 4) {  // every inlier duplicated, outliers too
      const Points3 copy = pts;
      pts.insert(pts.end(), copy.begin(), copy.end());
    }
    const auto fit = fitPlaneRansac(pts, opt);
    if (kind == 2 || kind == 3) {
      ASSERT_FALSE(fit);
      EXPECT_EQ(fit.error().code, kind == 2 ? ErrorCode::kDegenerate : ErrorCode::kInvalidInput);
      continue;
    }
    ASSERT_TRUE(fit) << fit.error().message;
    ASSERT_TRUE(fit->plane.n.allFinite() && std::isfinite(fit->plane.d) && std::isfinite(fit->rms));
    // With >= 60% inliers and confidence 0.999 the consensus plane is the true one;
    // an outlier lands in the 2e-6 su band with probability ~1e-6.
    EXPECT_LE(angleBetween(fit->plane.n, normal), 1e-6 + 1e4 * kEps * (1 + center.norm() / su));
    const std::size_t expected = static_cast<std::size_t>(inliers) * (kind == 4 ? 2 : 1);
    EXPECT_GE(fit->inliers.size(), expected);
    EXPECT_LE(fit->inliers.size(), expected + 2);
  }
  stress::report("plane fit (RANSAC)", cases);
}

}  // namespace
}  // namespace procam::geom
