#pragma once
// Synthetic cameras and scenes with exactly known geometry, shared by the geometry
// unit and stress tests.
#include <algorithm>
#include <cmath>
#include <random>

#include "core/types.hpp"
#include "geometry/camera_model.hpp"

namespace procam::testing {

inline geom::CameraModel makeCamera(const Vec3& eye, const Vec3& target, double f = 1000,
                                    int width = 1920, int height = 1080) {
  geom::CameraModel cam;
  cam.K.fx = f;
  cam.K.fy = f * 1.01;
  cam.K.cx = (width - 1) / 2.0 + 7.5;
  cam.K.cy = (height - 1) / 2.0 - 4.25;
  cam.K.skew = 0.3;
  cam.pose = geom::Pose::lookAt(eye, target, Vec3::UnitZ());
  cam.width = width;
  cam.height = height;
  return cam;
}

// Homography from camera A's image to camera B's image induced by the world plane
// z = 0: x = P[:, {0,1,3}] (X, Y, 1)ᵀ for points on that plane.
inline Mat3 planeHomography(const Mat34& Pa, const Mat34& Pb) {
  Mat3 A, B;
  A << Pa.col(0), Pa.col(1), Pa.col(3);
  B << Pb.col(0), Pb.col(1), Pb.col(3);
  return B * A.inverse();
}

// Largest transfer difference (pixels) between two homographies over a grid covering
// [0, w] x [0, h]; infinity if either maps a grid point to infinity.
inline double maxTransferDifference(const Mat3& H1, const Mat3& H2, double w, double h) {
  double worst = 0;
  for (int i = 0; i <= 10; ++i) {
    for (int j = 0; j <= 10; ++j) {
      const Vec3 p(w * i / 10.0, h * j / 10.0, 1.0);
      const Vec3 a = H1 * p, b = H2 * p;
      if (a.z() == 0 || b.z() == 0) return INFINITY;
      worst = std::max(worst, (a.hnormalized() - b.hnormalized()).norm());
    }
  }
  return worst;
}

inline Vec2 uniformPixel(std::mt19937_64& rng, double w, double h) {
  std::uniform_real_distribution<double> ux(0, w), uy(0, h);
  return {ux(rng), uy(rng)};
}

}  // namespace procam::testing
