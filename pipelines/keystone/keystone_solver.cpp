#include "keystone/keystone_solver.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <string>

namespace procam::keystone {
namespace {

bool validRotation(const Mat3& R) {
  return R.allFinite() && (R.transpose() * R - Mat3::Identity()).norm() < 1e-6 &&
         R.determinant() > 0;
}

}  // namespace

Mat3 wallToFramebuffer(const geom::Intrinsics& K, const Mat3& R) {
  Mat3 M;
  M.col(0) = R.col(0);  // X
  M.col(1) = R.col(2);  // Z
  M.col(2) = R.col(1);  // the wall's point (0, 1, 0)
  return K.matrix() * M;
}

Result<KeystoneSolution> solveKeystone(const KeystoneProblem& p) {
  if (p.width <= 0 || p.height <= 0 || p.content_width <= 0 || p.content_height <= 0)
    return fail(ErrorCode::kInvalidInput, "framebuffer and content sizes must be positive");
  const Mat3 K = p.K.matrix();
  if (!K.allFinite() || p.K.fx <= 0 || p.K.fy <= 0)
    return fail(ErrorCode::kInvalidInput, "intrinsics must be finite with fx, fy > 0");
  if (!validRotation(p.R)) return fail(ErrorCode::kInvalidInput, "R is not a rotation");
  // With M = [r1 r3 r2] orthonormal, the wall point of a corner is M^T K^-1 x: its
  // w is the corner ray's Y in the wall frame, and |(x, y, w)| the ray's length.
  return solveOnWall(wallToFramebuffer(p.K, p.R), p.width, p.height, p.content_width,
                     p.content_height, p.inscribe);
}

Result<KeystoneSolution> solveOnWall(const Mat3& wall_to_framebuffer, int width, int height,
                                     int content_width, int content_height,
                                     const InscribeOptions& inscribe) {
  if (width <= 0 || height <= 0 || content_width <= 0 || content_height <= 0)
    return fail(ErrorCode::kInvalidInput, "framebuffer and content sizes must be positive");
  const Eigen::JacobiSVD<Mat3> svd(wall_to_framebuffer);
  if (!wall_to_framebuffer.allFinite() ||
      !(svd.singularValues()(2) > 1e-12 * svd.singularValues()(0)))
    return fail(ErrorCode::kInvalidInput, "the wall's collineation is not finite or singular");
  KeystoneSolution s;
  s.wall_to_framebuffer = wall_to_framebuffer;
  const Mat3 fb_to_wall = s.wall_to_framebuffer.inverse();
  const double W = width, Hh = height;
  const std::array<Vec2, 4> fb = {Vec2(-0.5, -0.5), Vec2(W - 0.5, -0.5), Vec2(W - 0.5, Hh - 0.5),
                                  Vec2(-0.5, Hh - 0.5)};
  for (int i = 0; i < 4; ++i) {
    // The corner must land on the wall, with some margin, else the quadrilateral is
    // unbounded.
    const Vec3 w = fb_to_wall * fb[i].homogeneous();
    if (w.z() <= 1e-6 * w.norm())
      return fail(ErrorCode::kDegenerate,
                  "framebuffer corner " + std::to_string(i) + " does not reach the wall");
    s.wall_quad[i] = w.hnormalized();
  }

  const double aspect = double(content_width) / double(content_height);
  auto rect = largestInscribedRect(s.wall_quad, aspect, inscribe);
  if (!rect) return tl::unexpected(rect.error());
  s.rect = *rect;

  // Content pixel edges -> wall: u in [-0.5, Wc - 0.5] -> X in [left, right];
  // v in [-0.5, Hc - 0.5] -> Z from top to bottom (content y is down, wall Z is up).
  const double left = rect->centre.x() - rect->half_width;
  const double top = rect->centre.y() + rect->half_height;
  const double sx = 2 * rect->half_width / content_width;
  const double sz = 2 * rect->half_height / content_height;
  Mat3 content_to_wall;
  content_to_wall << sx, 0, left + 0.5 * sx, 0, -sz, top - 0.5 * sz, 0, 0, 1;
  s.H = s.wall_to_framebuffer * content_to_wall;
  if (std::abs(s.H(2, 2)) < 1e-15)
    return fail(ErrorCode::kDegenerate, "pre-warp maps the content origin to infinity");
  s.H /= s.H(2, 2);

  const double cw = content_width, ch = content_height;
  const std::array<Vec2, 4> content = {Vec2(-0.5, -0.5), Vec2(cw - 0.5, -0.5),
                                       Vec2(cw - 0.5, ch - 0.5), Vec2(-0.5, ch - 0.5)};
  for (int i = 0; i < 4; ++i) s.corners[i] = (s.H * content[i].homogeneous()).hnormalized();

  double quad_area2 = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec2& a = s.wall_quad[i];
    const Vec2& b = s.wall_quad[(i + 1) % 4];
    quad_area2 += a.x() * b.y() - a.y() * b.x();
  }
  s.scale = std::sqrt(rect->area() / (0.5 * std::abs(quad_area2)));
  if (!s.H.allFinite() || !std::isfinite(s.scale))
    return fail(ErrorCode::kIllConditioned, "keystone solution is not finite");
  return s;
}

}  // namespace procam::keystone
