// Route (b): projector intrinsics and pose from one calibrated camera and a blank
// plane at >= 2 orientations ([Raskar02] §7.3, [Raskar01b]).
//
// With the camera frame as reference, a point on plane i (m_i . X = 1) seen along
// the normalised camera ray x lies at X = x / (m_i . x), and the projector sees it at
// K (R X + t) ~ K (R + t m_i^T) x: one homography per plane. These homographies do
// not determine a general K, whatever the number of planes: for any vector w,
// K'R' = KR + (Kt) w^T (RQ-decomposed), t' = K'^-1 K t and m_i' = m_i - w reproduce
// every one of them exactly, a 3-parameter family. Zero skew, square pixels and a
// known horizontal principal point remove it (three constraints), which matches
// projectors: square pixels, lens shift only vertical. Then f, c_y, R, t and the
// planes follow from >= 2 orientations. The estimate minimises the projector-pixel
// reprojection error over all correspondences (LM), started from homography
// decompositions under a few focal-length and lens-shift guesses.
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <unsupported/Eigen/LevenbergMarquardt>
#include <unsupported/Eigen/NumericalDiff>

#include "calibration/projector_calibration.hpp"
#include "geometry/homography.hpp"

namespace procam::calib {
namespace {

constexpr int kIntrinsics = 2, kRotation = 3, kTranslation = 2, kPlane = 3;
constexpr int kShared = kIntrinsics + kRotation + kTranslation;
constexpr double kBehind = 1e4;  // residual for points behind a device

struct PlaneData {
  std::vector<Vec3> rays;  // normalised camera coordinates (x, y, 1)
  Points2 projector;
};

// t has one component fixed to +-1 (the largest), which removes the scale gauge.
struct Gauge {
  int axis = 0;
  double value = 1;
};

Vec3 translation(const Eigen::VectorXd& p, const Gauge& g) {
  Vec3 t;
  int k = 0;
  for (int a = 0; a < 3; ++a) t(a) = a == g.axis ? g.value : p(kIntrinsics + kRotation + k++);
  return t;
}

Mat3 rotation(const Eigen::VectorXd& p) {
  const Vec3 w = p.segment<3>(kIntrinsics);
  const double angle = w.norm();
  if (angle < 1e-15) return Mat3::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// Parameters: f, c_y | rotation vector (3) | t without its gauge component (2) |
// m_i (3 per plane). c_x is fixed.
struct Residuals : Eigen::DenseFunctor<double> {
  const std::vector<PlaneData>* planes = nullptr;
  Gauge gauge;
  double cx = 0;

  Residuals(const std::vector<PlaneData>& data, Gauge g, double cx_known, int values)
      : Eigen::DenseFunctor<double>(kShared + kPlane * static_cast<int>(data.size()), values),
        planes(&data),
        gauge(g),
        cx(cx_known) {}

  int operator()(const Eigen::VectorXd& p, Eigen::VectorXd& r) const {
    const Mat3 R = rotation(p);
    const Vec3 t = translation(p, gauge);
    Eigen::Index k = 0;
    for (std::size_t i = 0; i < planes->size(); ++i) {
      const Vec3 m = p.segment<3>(kShared + kPlane * static_cast<Eigen::Index>(i));
      const PlaneData& d = (*planes)[i];
      for (std::size_t j = 0; j < d.rays.size(); ++j, k += 2) {
        const double s = m.dot(d.rays[j]);
        const Vec3 y = s > 1e-12 ? Vec3(R * (d.rays[j] / s) + t) : Vec3(0, 0, -1);
        if (y.z() <= 1e-12) {
          r(k) = r(k + 1) = kBehind;
          continue;
        }
        r(k) = p(0) * y.x() / y.z() + cx - d.projector[j].x();
        r(k + 1) = p(0) * y.y() / y.z() + p(1) - d.projector[j].y();
      }
    }
    return 0;
  }
};

int residualCount(const std::vector<PlaneData>& planes) {
  int n = 0;
  for (const auto& d : planes) n += 2 * static_cast<int>(d.rays.size());
  return n;
}

double solve(const std::vector<PlaneData>& planes, const Gauge& g, double cx, Eigen::VectorXd& p,
             int iterations) {
  Residuals f(planes, g, cx, residualCount(planes));
  Eigen::NumericalDiff<Residuals> nd(f);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Residuals>> lm(nd);
  lm.setMaxfev(iterations * (static_cast<int>(p.size()) + 1));
  lm.setXtol(1e-12);
  lm.setFtol(1e-14);
  lm.minimize(p);
  Eigen::VectorXd r(f.values());
  f(p, r);
  return std::sqrt(r.squaredNorm() / std::max<Eigen::Index>(1, r.size() / 2));
}

std::vector<PlaneData> subsample(const std::vector<PlaneData>& planes, std::size_t per_plane) {
  std::vector<PlaneData> out(planes.size());
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const std::size_t n = planes[i].rays.size();
    const double stride = std::max(1.0, static_cast<double>(n) / per_plane);
    for (double j = 0; j < n; j += stride) {
      out[i].rays.push_back(planes[i].rays[static_cast<std::size_t>(j)]);
      out[i].projector.push_back(planes[i].projector[static_cast<std::size_t>(j)]);
    }
  }
  return out;
}

struct PlaneSolution {
  Mat3 R;
  Vec3 t;  // T / d_i
  Vec3 n;
};

// Decompositions of K0^-1 H = R + (T/d) n^T that keep the data in front of the
// camera and of the projector.
std::vector<PlaneSolution> decompose(const Mat3& H, const Mat3& K0, const PlaneData& d) {
  Mat3 M = K0.inverse() * H;
  double z = 0;
  for (const Vec3& x : d.rays) z += (M * x).z();
  if (z < 0) M = -M;
  const Eigen::JacobiSVD<Mat3> svd(M);
  M /= svd.singularValues()(1);
  cv::Mat Mcv, Kcv = cv::Mat::eye(3, 3, CV_64F);
  cv::eigen2cv(M, Mcv);
  std::vector<cv::Mat> Rs, ts, ns;
  cv::decomposeHomographyMat(Mcv, Kcv, Rs, ts, ns);
  std::vector<PlaneSolution> out;
  for (std::size_t i = 0; i < Rs.size(); ++i) {
    PlaneSolution s;
    cv::cv2eigen(Rs[i], s.R);
    Eigen::Vector3d t, n;
    cv::cv2eigen(ts[i], t);
    cv::cv2eigen(ns[i], n);
    s.t = t;
    s.n = n;
    int front = 0;
    for (const Vec3& x : d.rays) {
      const double sx = s.n.dot(x);
      front += sx > 0 && (s.R * (x / sx) + s.t).z() > 0;
    }
    if (front > 0.9 * static_cast<double>(d.rays.size())) out.push_back(s);
  }
  return out;
}

double angleBetween(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

// Initial parameters for one focal-length guess, or an empty vector.
Eigen::VectorXd initialise(const std::vector<PlaneData>& planes, const std::vector<Mat3>& H,
                           const Mat3& K0, Gauge& gauge) {
  std::vector<std::vector<PlaneSolution>> sols;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    sols.push_back(decompose(H[i], K0, planes[i]));
    if (sols.back().empty()) return {};
  }
  // The first plane's solution whose rotation the other planes agree with best.
  double best = std::numeric_limits<double>::infinity();
  std::vector<std::size_t> pick(planes.size(), 0);
  for (std::size_t a = 0; a < sols[0].size(); ++a) {
    double cost = 0;
    std::vector<std::size_t> choice(planes.size(), a);
    for (std::size_t i = 1; i < planes.size(); ++i) {
      double b_best = std::numeric_limits<double>::infinity();
      for (std::size_t b = 0; b < sols[i].size(); ++b) {
        const double c = angleBetween(sols[0][a].R, sols[i][b].R);
        if (c < b_best) b_best = c, choice[i] = b;
      }
      cost += b_best;
    }
    if (cost < best) best = cost, pick = choice;
  }
  const PlaneSolution& first = sols[0][pick[0]];
  Vec3 t = first.t;  // gauge d_1 = 1
  const double t_norm = t.norm();
  if (!(t_norm > 1e-9)) return {};
  Eigen::VectorXd p(kShared + kPlane * static_cast<int>(planes.size()));
  p(0) = K0(0, 0);
  p(1) = K0(1, 2);
  const Eigen::AngleAxisd aa(first.R);
  p.segment<3>(kIntrinsics) = aa.angle() * aa.axis();
  t.cwiseAbs().maxCoeff(&gauge.axis);
  const double scale = std::abs(t(gauge.axis));
  gauge.value = t(gauge.axis) > 0 ? 1.0 : -1.0;
  int k = 0;
  for (int a = 0; a < 3; ++a)
    if (a != gauge.axis) p(kIntrinsics + kRotation + k++) = t(a) / scale;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const PlaneSolution& s = sols[i][pick[i]];
    // t_i = T / d_i, so m_i = n_i / d_i = n_i |t_i| / |T|, with |T| = |t_1| here.
    const Vec3 m = s.n * (s.t.norm() / t_norm);
    p.segment<3>(kShared + kPlane * static_cast<Eigen::Index>(i)) = m * scale;
  }
  return p;
}

}  // namespace

Result<ProjectorCalibration> calibrateProjectorFromPlanes(const geom::CameraModel& camera,
                                                          std::span<const PlaneView> views,
                                                          const PlaneRouteOptions& o) {
  if (views.size() < 2)
    return fail(ErrorCode::kTooFewPoints,
                "route (b) needs the plane at two or more orientations (got " +
                    std::to_string(views.size()) + ")");
  std::vector<PlaneData> planes(views.size());
  std::vector<Mat3> H;
  const Mat3 Kc_inv = camera.K.matrix().inverse();
  Vec2 projector_max(0, 0);
  for (std::size_t i = 0; i < views.size(); ++i) {
    const PlaneView& v = views[i];
    if (v.camera.size() != v.projector.size())
      return fail(ErrorCode::kInvalidInput, "plane view: camera and projector point counts differ");
    Points2 normalised;
    for (std::size_t j = 0; j < v.camera.size(); ++j) {
      auto ideal = camera.undistortPixel(v.camera[j]);
      if (!ideal || !v.projector[j].allFinite()) continue;
      const Vec3 x = Kc_inv * Vec3(ideal->x(), ideal->y(), 1.0);
      planes[i].rays.push_back(x / x.z());
      planes[i].projector.push_back(v.projector[j]);
      normalised.emplace_back(x.x() / x.z(), x.y() / x.z());
      projector_max = projector_max.cwiseMax(v.projector[j]);
    }
    if (planes[i].rays.size() < 8)
      return fail(ErrorCode::kTooFewPoints,
                  "plane orientation " + std::to_string(i) + " has fewer than 8 usable points");
    auto h = geom::fitHomography(normalised, planes[i].projector);
    if (!h) return tl::unexpected(h.error());
    H.push_back(h->H);
  }

  // Multi-start over focal length and vertical principal point (projectors often
  // have a strong lens shift); keep the lowest reprojection error.
  const std::vector<PlaneData> coarse = subsample(planes, 250);
  const double w = o.projector_width > 0 ? o.projector_width : projector_max.x() + 1;
  const double h = o.projector_height > 0 ? o.projector_height : projector_max.y() + 1;
  const double cx = o.principal_x ? *o.principal_x : 0.5 * (w - 1);
  double best_rms = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best;
  Gauge best_gauge;
  for (double f : {0.8, 1.2, 1.7, 2.4, 3.4})
    for (double cy : {0.5, 0.85, 1.1}) {
      Mat3 K0 = Mat3::Identity();
      K0(0, 0) = K0(1, 1) = f * w;
      K0(0, 2) = cx;
      K0(1, 2) = cy * h;
      Gauge g;
      Eigen::VectorXd p = initialise(planes, H, K0, g);
      if (p.size() == 0) continue;
      const double rms = solve(coarse, g, cx, p, 100);
      if (std::isfinite(rms) && rms < best_rms) best_rms = rms, best = p, best_gauge = g;
    }
  if (best.size() == 0)
    return fail(ErrorCode::kNoConvergence, "route (b): no consistent plane decomposition found");

  const std::vector<PlaneData> fine =
      subsample(planes, static_cast<std::size_t>(std::max(50, o.max_points_per_plane)));
  solve(fine, best_gauge, cx, best, 200);

  ProjectorCalibration c;
  c.points = 0;
  for (const auto& d : planes) c.points += static_cast<int>(d.rays.size());
  Residuals all(planes, best_gauge, cx, residualCount(planes));
  Eigen::VectorXd r(all.values());
  all(best, r);
  c.rms_px = std::sqrt(r.squaredNorm() / (r.size() / 2));
  if (!std::isfinite(c.rms_px) || !best.allFinite() || best(0) <= 0)
    return fail(ErrorCode::kNoConvergence, "route (b): the solution did not converge");

  // Distinct plane orientations are what makes K observable.
  double widest = 0;
  for (std::size_t i = 1; i < planes.size(); ++i) {
    const Vec3 m0 = best.segment<3>(kShared).normalized();
    const Vec3 mi = best.segment<3>(kShared + kPlane * static_cast<Eigen::Index>(i)).normalized();
    widest = std::max(widest, std::acos(std::clamp(m0.dot(mi), -1.0, 1.0)));
  }
  if (widest * 180 / M_PI < o.min_plane_angle_deg)
    return fail(ErrorCode::kDegenerate, "route (b): the plane orientations differ by less than " +
                                            std::to_string(o.min_plane_angle_deg) +
                                            " degrees; tilt the plane more");

  c.K = {best(0), best(0), cx, best(1), 0.0};
  const Mat3 R = rotation(best);
  Vec3 t = translation(best, best_gauge);
  const double d1 = 1.0 / best.segment<3>(kShared).norm();  // camera to plane 1, model units
  if (o.first_plane_distance) {
    t *= *o.first_plane_distance / d1;
  } else {
    t.normalize();
    c.scale_known = false;
  }
  // Projector from camera, composed with the camera's world pose.
  c.pose.R = R * camera.pose.R;
  c.pose.t = R * camera.pose.t + t;
  return c;
}

}  // namespace procam::calib
