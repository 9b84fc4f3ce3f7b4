#pragma once
// Rigid (optionally similarity) transform between point sets, [Raskar02] eq. 4.2.
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::geom {

struct RigidFit {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double scale = 1.0;  // 1 unless with_scale
  double rms = 0;      // RMS of ||to - (s R from + t)||
};

// to ≈ s R from + t; n >= 3 non-collinear points. kDegenerate when either set is
// coincident or collinear (second/first principal extent < 1e-5, or within the
// rounding of the coordinates); R is always a rotation (det +1).
Result<RigidFit> fitRigidTransform(std::span<const Vec3> from, std::span<const Vec3> to,
                                   bool with_scale = false);

}  // namespace procam::geom
