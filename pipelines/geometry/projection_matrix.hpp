#pragma once
// 3x4 projection matrix from 3D-2D correspondences and its decomposition
// ([Raskar02] §4.1.1 eq. 4.1, "Projector Calibration").
#include <span>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::geom {

struct ProjectionFit {
  Mat34 P = Mat34::Zero();  // ||P||_F = 1, sign chosen so points lie in front (w > 0)
  double condition = 0;     // of the normalised DLT system
  double rms = 0;           // reprojection RMS in pixels
  int iterations = 0;
};

struct ProjectionOptions {
  bool refine = true;
  int max_iterations = 100;
  // Points whose smallest principal spread is below this fraction of the largest
  // are treated as coplanar ([Raskar02] §4.1.1: the planar depth-scale ambiguity).
  double coplanar_ratio = 1e-3;
  double max_condition = 1e8;  // of the normalised DLT system; larger -> kIllConditioned
};

// n >= 6 pairs; kCoplanar for (near-)coplanar 3D points, kTooFewPoints, kDegenerate.
Result<ProjectionFit> fitProjectionMatrix(std::span<const Vec3> world, std::span<const Vec2> pixels,
                                          const ProjectionOptions& options = {});

struct KRt {
  Intrinsics K;  // fx, fy > 0
  Pose pose;     // det R = +1
};

// RQ decomposition with signs fixed (positive focal lengths, det R = +1). The overall
// sign of P is taken from det of its left 3x3 block (that of a real camera K R is
// positive), so the result does not depend on the sign P is given in. kDegenerate when
// that block is singular (camera at infinity).
Result<KRt> decomposeProjectionMatrix(const Mat34& P);

}  // namespace procam::geom
