#pragma once
// Random scenes for the planar 3D path ([Raskar02] §4.2.2-4.2.3, eq. 4.10): an oblique projector
// lighting a wall, a tracked viewer in front of it, S bounding the projector's image and
// A'4x4 P_T in this project's pixel convention.
#include <optional>
#include <random>

#include "keystone/head_tracked.hpp"
#include "render/gl_conventions.hpp"
#include "render_test_rig.hpp"

namespace procam::test {

struct Planar3dScene {
  Mat34 P;   // projector, world -> pixels
  Vec3 eye;  // tracked viewer
  keystone::DisplayRect S;
  Mat4 pixel3d;  // A'4x4 P_T in this project's pixel convention
};

// Wall: plane y = 3 (world +Z up), viewer side y < 3; u = +X, v = +Z. nullopt when the
// draw gives no usable S or |a31| + |a32| >= 1 (eq. 4.9 cannot hold).
inline std::optional<Planar3dScene> randomPlanar3dScene(std::mt19937& rng, int width, int height,
                                                        double near = 0.05, double far = 50.0) {
  std::uniform_real_distribution<double> U(-1, 1);
  Planar3dScene s;
  const Vec3 centre(0.5 * U(rng), 0.2 + 2.0 * (U(rng) + 1) / 2, 1.2 + 0.3 * U(rng));
  const Vec3 target(0.8 * U(rng), 3.0, 1.3 + 0.5 * U(rng));
  Vec3 up = Vec3::UnitZ() + 0.15 * Vec3(U(rng), U(rng), 0);
  s.P = lookAtProjection(1.3 * width, (width - 1) / 2.0, (height - 1) / 2.0, centre, target, up);
  s.eye = Vec3(1.2 * U(rng), 0.3 + 1.5 * (U(rng) + 1) / 2, 1.6 + 0.4 * U(rng));
  auto S = keystone::boundingDisplayRect(s.P, width, height, Vec3(0, 3, 0), Vec3::UnitX(),
                                         Vec3::UnitZ());
  if (!S) return std::nullopt;
  s.S = *S;
  auto path = keystone::headTrackedPath(s.eye, s.S, near, far, s.P, width, height);
  if (!path) return std::nullopt;
  // Keystone's projector NDC has y up with image row 0 at the top.
  const Mat4 clip_top =
      render::glConventions(width, height, render::GlOrigin::kRow0AtGlTop).clip_from_pixel;
  s.pixel3d = clip_top.inverse() * path->single_pass;
  return s;
}

// Point of S at normalised (a, b) in [0, 1]^2.
inline Vec3 onS(const keystone::DisplayRect& S, double a, double b) {
  return S.corner + a * S.width * S.u + b * S.height * S.v;
}

}  // namespace procam::test
