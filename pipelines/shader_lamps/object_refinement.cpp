#include "shader_lamps/object_refinement.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <vector>

#include "shader_lamps/object_model.hpp"

namespace procam::lamps {
namespace {

constexpr long kMinPoints = 50;
// Smallest over largest eigenvalue of the normal equations (about the centroid, rotations
// scaled by the points' spread) below which a direction counts as not fixed by the
// points: its step would carry the noise amplified over thirty times.
constexpr double kMinConditioning = 1e-3;

Result<void> checkMesh(const geom::TriangleMesh& m) {
  const int n = static_cast<int>(m.vertices.size());
  for (const Vec3& v : m.vertices)
    if (!v.allFinite()) return fail(ErrorCode::kInvalidInput, "a measured vertex is not finite");
  for (const auto& f : m.faces)
    if (f.minCoeff() < 0 || f.maxCoeff() >= n)
      return fail(ErrorCode::kInvalidInput, "a measured face names a vertex it does not have");
  return {};
}

struct Oriented {
  Vec3 point, normal;
};

// Measured vertices with area-weighted normals; vertices of no face are left out.
std::vector<Oriented> orientedVertices(const geom::TriangleMesh& m) {
  std::vector<Vec3> n(m.vertices.size(), Vec3::Zero());
  for (const auto& f : m.faces) {
    const Vec3 a = m.vertices[f.x()], b = m.vertices[f.y()], c = m.vertices[f.z()];
    const Vec3 area = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n[f[k]] += area;
  }
  std::vector<Oriented> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const double len = n[i].norm();
    if (len > 0) out.push_back({m.vertices[i], n[i] / len});
  }
  return out;
}

struct Pull {
  Vec3 p, n;  // the model's point and normal (model frame)
  double r;   // signed distance of the measured vertex from the model's tangent plane
};

// The model's surface beside a measured vertex (model frame): the nearer hit along the
// vertex's normal, either way, within `radius`, whose normal agrees within the angle.
std::optional<Pull> pullOf(const ObjectModel& model, const Vec3& v, const Vec3& nv, double radius,
                           double cos_max) {
  std::optional<Pull> best;
  double nearest = radius;
  for (const double side : {1.0, -1.0}) {
    const Vec3 dir = side * nv;
    const geom::Ray ray{v - radius * dir, dir};
    auto hit = model.intersect(ray, {0, 2 * radius});
    if (!hit) continue;
    const double d = (hit->point - v).norm();
    if (d > nearest || std::abs(hit->normal.dot(nv)) < cos_max) continue;
    const Vec3 n = hit->normal.dot(nv) >= 0 ? hit->normal : Vec3(-hit->normal);
    best = Pull{hit->point, n, n.dot(v - hit->point)};
    nearest = d;
  }
  return best;
}

Mat3 rotationOf(const Vec3& omega) {
  const double angle = omega.norm();
  if (angle < 1e-300) return Mat3::Identity();
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

}  // namespace

Result<ObjectRefinement> refinePlacement(std::span<const geom::TriangleMesh> measured,
                                         const geom::TriangleMesh& model,
                                         const ObjectPlacement& start, const RefineOptions& o) {
  if (!(o.max_distance_m > 0 && o.max_distance_m <= 0.1) ||
      !(o.final_distance_m > 0 && o.final_distance_m <= o.max_distance_m))
    return fail(ErrorCode::kInvalidInput,
                "the search radii must lie in (0, 0.1] m, the last not above the first");
  if (!(o.max_normal_deg > 0 && o.max_normal_deg < 90) || o.iterations < 1 || o.iterations > 200)
    return fail(ErrorCode::kInvalidInput,
                "the normals' angle must lie in (0, 90) degrees and the iterations in 1..200");
  if (!start.R.allFinite() || !start.t.allFinite() ||
      !(start.R * start.R.transpose()).isApprox(Mat3::Identity(), 1e-6) ||
      !(start.R.determinant() > 0))
    return fail(ErrorCode::kInvalidInput, "the start is not a rigid placement");
  auto shape = ObjectModel::build(model);
  if (!shape) return tl::unexpected(shape.error());
  std::vector<Oriented> points;
  for (const geom::TriangleMesh& m : measured) {
    if (auto ok = checkMesh(m); !ok) return tl::unexpected(ok.error());
    const auto v = orientedVertices(m);
    points.insert(points.end(), v.begin(), v.end());
  }
  const double cos_max = std::cos(o.max_normal_deg * std::numbers::pi / 180);
  ObjectRefinement out;
  out.candidates = static_cast<long>(points.size());
  Mat3 R = start.R;
  Vec3 t = start.t;
  std::vector<Pull> pulls;
  for (int it = 0; it < o.iterations; ++it) {
    // The radius narrows geometrically from the first to the last over half the
    // iterations, then stays.
    const double f = std::min(1.0, it / std::max(1.0, o.iterations / 2.0));
    const double radius = o.max_distance_m * std::pow(o.final_distance_m / o.max_distance_m, f);
    pulls.clear();
    for (const Oriented& q : points) {
      // Into the model's frame: the model stays, the measured points move.
      const Vec3 v = R.transpose() * (q.point - t), nv = R.transpose() * q.normal;
      if (auto pull = pullOf(*shape, v, nv, radius, cos_max)) pulls.push_back(*pull);
    }
    if (static_cast<long>(pulls.size()) < kMinPoints)
      return fail(ErrorCode::kTooFewPoints,
                  std::to_string(pulls.size()) +
                      " measured points lie on the model (50 needed): is it placed where it "
                      "stands, and did calibration measure the surface there?");
    // min sum (r - (p x n) . w - n . tau)^2 about the centroid c, rotations scaled by
    // the spread s so that both halves of the unknown have the same units.
    Vec3 c = Vec3::Zero();
    for (const Pull& p : pulls) c += p.p;
    c /= static_cast<double>(pulls.size());
    double s = 0;
    for (const Pull& p : pulls) s += (p.p - c).squaredNorm();
    s = std::sqrt(s / static_cast<double>(pulls.size()));
    if (!(s > 0)) return fail(ErrorCode::kDegenerate, "the measured points on the model coincide");
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    double sq = 0, worst = 0;
    for (const Pull& p : pulls) {
      Eigen::Matrix<double, 6, 1> j;
      j << ((p.p - c) / s).cross(p.n), p.n;
      A += j * j.transpose();
      b += j * p.r;
      sq += p.r * p.r;
      worst = std::max(worst, std::abs(p.r));
    }
    // Directions the points do not fix (a face the cameras could not both see leaves the
    // model free to slide along the others) are not moved: the start's pose stands there.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(A);
    const Eigen::Matrix<double, 6, 1> along = eig.eigenvectors().transpose() * b;
    Eigen::Matrix<double, 6, 1> step = Eigen::Matrix<double, 6, 1>::Zero();
    std::vector<Eigen::Matrix<double, 6, 1>> free;
    for (int k = 0; k < 6; ++k) {
      if (eig.eigenvalues()(k) > kMinConditioning * eig.eigenvalues()(5)) {
        step(k) = along(k) / eig.eigenvalues()(k);
      } else {
        free.push_back(eig.eigenvectors().col(k));
      }
    }
    const Eigen::Matrix<double, 6, 1> x = eig.eigenvectors() * step;
    out.free.clear();
    for (const auto& f : free) {
      // In the world: a turn or a slide, whichever the direction is mostly.
      FreeDirection d;
      d.turn = f.head<3>().norm() > f.tail<3>().norm();
      const Vec3 fw = f.head<3>() / s, ftau = f.tail<3>();
      d.axis = (R * (d.turn ? fw : ftau)).normalized();
      // m -> fw x (m - c) + ftau turns about the axis through c + (fw x ftau) / |fw|^2
      // (the part of ftau along fw slides along it).
      const Vec3 pivot = d.turn ? Vec3(c + fw.cross(ftau) / fw.squaredNorm()) : c;
      d.through = R * pivot + t;
      out.free.push_back(d);
    }
    const Vec3 w = x.head<3>() / s, tau = x.tail<3>();
    // The model moves by m -> dR (m - c) + c + tau (dR = exp(w)), so world = R m' + t.
    const Mat3 dR = rotationOf(w);
    const Vec3 shift = c + tau - dR * c;
    t = R * shift + t;
    R = R * dR;
    out.iterations = it + 1;
    out.points = static_cast<long>(pulls.size());
    out.placement.rms_m = std::sqrt(sq / static_cast<double>(pulls.size()));
    out.placement.max_m = worst;
    if (w.norm() < 1e-9 && tau.norm() < 1e-9 && f >= 1) break;
  }
  // Re-orthonormalise what the products of small rotations left.
  Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  R = svd.matrixU() * svd.matrixV().transpose();
  out.placement.R = R;
  out.placement.t = t;
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& v : model.vertices) centroid += v;
  centroid /= static_cast<double>(std::max<std::size_t>(1, model.vertices.size()));
  out.moved_m = ((R * centroid + t) - (start.R * centroid + start.t)).norm();
  out.turned_deg = Eigen::AngleAxisd(R * start.R.transpose()).angle() * 180 / std::numbers::pi;
  return out;
}

}  // namespace procam::lamps
