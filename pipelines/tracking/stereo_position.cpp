#include "tracking/stereo_position.hpp"

#include <cmath>

#include "geometry/rigid.hpp"
#include "geometry/triangulate.hpp"

namespace procam::tracking {

Result<TriangulatedPoint> triangulateLed(std::span<const geom::CameraModel> cameras,
                                         std::span<const Vec2> pixels, double pixel_sigma) {
  if (cameras.size() < 2 || pixels.size() != cameras.size())
    return fail(ErrorCode::kTooFewPoints, "triangulation needs the LED in >= 2 cameras");
  std::vector<Mat34> P;
  Points2 ideal;
  for (size_t i = 0; i < cameras.size(); ++i) {
    auto u = cameras[i].undistortPixel(pixels[i]);
    if (!u) return tl::unexpected(u.error());
    ideal.push_back(*u);
    P.push_back(cameras[i].projectionMatrix());
  }
  auto X = geom::triangulateLinear(P, ideal);
  if (!X) return tl::unexpected(X.error());

  // Covariance sigma^2 (J^T J)^-1 with J = d(ideal pixels)/dX (Gauss-Newton).
  Eigen::MatrixXd J(2 * P.size(), 3);
  double sq = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    const Vec3 h = P[i] * X->homogeneous();
    if (h.z() <= 0) return fail(ErrorCode::kDegenerate, "triangulated LED behind a camera");
    const Vec2 q = h.hnormalized();
    sq += (q - ideal[i]).squaredNorm();
    for (int r = 0; r < 2; ++r)
      J.row(2 * static_cast<Eigen::Index>(i) + r) =
          (P[i].row(r).head<3>() - q(r) * P[i].row(2).head<3>()) / h.z();
  }
  const Mat3 info = J.transpose() * J;
  Eigen::FullPivLU<Mat3> lu(info);
  if (!lu.isInvertible()) return fail(ErrorCode::kDegenerate, "triangulation is ill-posed");
  return TriangulatedPoint{*X, pixel_sigma * pixel_sigma * lu.inverse(),
                           std::sqrt(sq / static_cast<double>(P.size()))};
}

Result<StereoConstellation> fitConstellation(std::span<const Vec3> leds,
                                             std::span<const TriangulatedPoint> measured) {
  if (leds.size() != measured.size())
    return fail(ErrorCode::kInvalidInput, "one measurement per LED");
  Points3 world;
  Mat3 cov_sum = Mat3::Zero();
  for (const TriangulatedPoint& m : measured) {
    world.push_back(m.point);
    cov_sum += m.covariance;
  }
  auto fit = geom::fitRigidTransform(leds, world);
  if (!fit) return tl::unexpected(fit.error());
  const double n = static_cast<double>(leds.size());
  StereoConstellation out;
  out.pose.R = fit->R;
  out.pose.t = fit->t;
  out.position = fit->t;  // image of the constellation origin
  // The fit's translation at the origin: mean of the LED errors plus rotation
  // leverage; the mean term dominates for an origin near the LEDs' centroid.
  out.covariance = cov_sum / (n * n);
  out.rms_m = fit->rms;
  return out;
}

}  // namespace procam::tracking
