#include "keystone/keystone_solver.hpp"

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

  KeystoneSolution s;
  s.wall_to_framebuffer = wallToFramebuffer(p.K, p.R);
  const Mat3 fb_to_wall = s.wall_to_framebuffer.inverse();
  const double W = p.width, Hh = p.height;
  const std::array<Vec2, 4> fb = {Vec2(-0.5, -0.5), Vec2(W - 0.5, -0.5), Vec2(W - 0.5, Hh - 0.5),
                                  Vec2(-0.5, Hh - 0.5)};
  const Mat3 Kinv = K.inverse();
  for (int i = 0; i < 4; ++i) {
    // Ray of the corner in the wall frame; it must head into the wall (Y > 0) with
    // some margin, else the quadrilateral is unbounded.
    const Vec3 ray = p.R.transpose() * (Kinv * fb[i].homogeneous());
    if (ray.y() <= 1e-6 * ray.norm())
      return fail(ErrorCode::kDegenerate,
                  "framebuffer corner " + std::to_string(i) + " does not reach the wall");
    const Vec3 w = fb_to_wall * fb[i].homogeneous();
    s.wall_quad[i] = w.hnormalized();
  }

  const double aspect = double(p.content_width) / double(p.content_height);
  auto rect = largestInscribedRect(s.wall_quad, aspect, p.inscribe);
  if (!rect) return tl::unexpected(rect.error());
  s.rect = *rect;

  // Content pixel edges -> wall: u in [-0.5, Wc - 0.5] -> X in [left, right];
  // v in [-0.5, Hc - 0.5] -> Z from top to bottom (content y is down, wall Z is up).
  const double left = rect->centre.x() - rect->half_width;
  const double top = rect->centre.y() + rect->half_height;
  const double sx = 2 * rect->half_width / p.content_width;
  const double sz = 2 * rect->half_height / p.content_height;
  Mat3 content_to_wall;
  content_to_wall << sx, 0, left + 0.5 * sx, 0, -sz, top - 0.5 * sz, 0, 0, 1;
  s.H = s.wall_to_framebuffer * content_to_wall;
  if (std::abs(s.H(2, 2)) < 1e-15)
    return fail(ErrorCode::kDegenerate, "pre-warp maps the content origin to infinity");
  s.H /= s.H(2, 2);

  const double cw = p.content_width, ch = p.content_height;
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
