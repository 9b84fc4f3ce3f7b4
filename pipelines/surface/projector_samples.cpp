#include "surface/projector_samples.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace procam::surface {
namespace {

// Sufficient statistics of x = c0 + A d, with d = projector offset from the node.
struct NodeFit {
  Eigen::Matrix3d dd = Eigen::Matrix3d::Zero();  // sum of [1 dx dy]^T [1 dx dy]
  Eigen::Matrix<double, 3, 2> dx = Eigen::Matrix<double, 3, 2>::Zero();  // sum of [1 dx dy]^T x^T
  int count = 0;
};

// Projector pixels per camera pixel (sqrt |det J| of the decoded map), at its 90th
// percentile: a camera sees a wide surface at very different distances (a curved wall
// 2.5 to 5 m away), and a neighbourhood sized for the median holds too few camera
// pixels where the camera is farthest (a quarter of a cylinder wall's nodes were lost).
double projectorPixelsPerCameraPixel(const sl::Decoded& d) {
  std::vector<double> scale;
  for (int y = 0; y + 1 < d.u.rows; y += 3) {
    const float *u = d.u.ptr<float>(y), *v = d.v.ptr<float>(y);
    const float *u1 = d.u.ptr<float>(y + 1), *v1 = d.v.ptr<float>(y + 1);
    const std::uint8_t *f = d.flags.ptr<std::uint8_t>(y), *f1 = d.flags.ptr<std::uint8_t>(y + 1);
    for (int x = 0; x + 1 < d.u.cols; x += 3) {
      if (f[x] || f[x + 1] || f1[x]) continue;
      const double det = (u[x + 1] - u[x]) * (v1[x] - v[x]) - (v[x + 1] - v[x]) * (u1[x] - u[x]);
      scale.push_back(std::sqrt(std::abs(det)));
    }
  }
  if (scale.empty()) return 1.0;
  const std::size_t at = scale.size() * 9 / 10;
  std::nth_element(scale.begin(), scale.begin() + at, scale.end());
  return std::clamp(scale[at], 0.0, 64.0);
}

}  // namespace

Result<ProjectorSamples> sampleProjectorGrid(const sl::Decoded& d, int width, int height,
                                             const SampleOptions& o) {
  if (o.step < 1 || width < 1 || height < 1 || !(o.radius > 0) || o.min_pixels < 3)
    return fail(ErrorCode::kInvalidInput, "projector sampling: invalid step, size or radius");
  if (d.u.empty() || d.u.type() != CV_32F || d.v.size() != d.u.size() ||
      d.flags.size() != d.u.size() || d.confidence.size() != d.u.size())
    return fail(ErrorCode::kInvalidInput, "projector sampling: malformed decoded map");
  ProjectorSamples s;
  s.step = o.step;
  s.nodes_x = (width - 1) / o.step + 1;
  s.nodes_y = (height - 1) / o.step + 1;
  std::vector<NodeFit> fits(static_cast<std::size_t>(s.nodes_x) * s.nodes_y);
  const double r = std::max({o.radius, 0.5 * o.step, 1.5 * projectorPixelsPerCameraPixel(d)});
  for (int y = 0; y < d.u.rows; ++y) {
    const float* u = d.u.ptr<float>(y);
    const float* v = d.v.ptr<float>(y);
    const float* c = d.confidence.ptr<float>(y);
    const std::uint8_t* f = d.flags.ptr<std::uint8_t>(y);
    for (int x = 0; x < d.u.cols; ++x) {
      if (f[x] != 0 || c[x] < o.min_confidence) continue;
      const int i0 = std::max(0, static_cast<int>(std::ceil((u[x] - r) / o.step)));
      const int i1 = std::min(s.nodes_x - 1, static_cast<int>(std::floor((u[x] + r) / o.step)));
      const int j0 = std::max(0, static_cast<int>(std::ceil((v[x] - r) / o.step)));
      const int j1 = std::min(s.nodes_y - 1, static_cast<int>(std::floor((v[x] + r) / o.step)));
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const Eigen::Vector3d a(1.0, u[x] - i * o.step, v[x] - j * o.step);
          NodeFit& n = fits[static_cast<std::size_t>(j) * s.nodes_x + i];
          n.dd.noalias() += a * a.transpose();
          n.dx.noalias() += a * Eigen::RowVector2d(x, y);
          ++n.count;
        }
    }
  }
  s.index.assign(fits.size(), -1);
  for (int j = 0; j < s.nodes_y; ++j)
    for (int i = 0; i < s.nodes_x; ++i) {
      const NodeFit& n = fits[static_cast<std::size_t>(j) * s.nodes_x + i];
      if (n.count < o.min_pixels) continue;
      // Near the projector's border the neighbourhood is one-sided and its edge
      // pixels are partly lit: no sample there.
      const double px = i * o.step, py = j * o.step;
      if (px < r - 0.5 || py < r - 0.5 || px > width - 0.5 - r || py > height - 0.5 - r) continue;
      // The node must lie inside the decoded neighbourhood, not at its rim (the
      // mean offset is then small against the spread), and the system well posed.
      const Eigen::Vector2d mean = n.dd.block<2, 1>(1, 0) / n.count;
      const Eigen::Matrix2d cov = n.dd.block<2, 2>(1, 1) / n.count - mean * mean.transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
      const double spread = std::sqrt(std::max(eig.eigenvalues()(0), 0.0));
      if (spread < 0.2 * r || mean.norm() > 0.5 * r) continue;
      const Eigen::LDLT<Eigen::Matrix3d> ldlt(n.dd);
      if (ldlt.info() != Eigen::Success) continue;
      const Eigen::Matrix<double, 3, 2> coef = ldlt.solve(n.dx);
      const Vec2 cam = coef.row(0).transpose();
      if (!cam.allFinite()) continue;
      s.index[static_cast<std::size_t>(j) * s.nodes_x + i] =
          static_cast<std::int32_t>(s.camera.size());
      s.camera.push_back(cam);
      s.projector.emplace_back(i * o.step, j * o.step);
    }
  return s;
}

}  // namespace procam::surface
