#include "render/projective_mesh.hpp"

#include <limits>

#include "render/raster.hpp"

namespace procam::render {
namespace {

Result<void> validate(const SurfaceMesh& mesh) {
  const int n = static_cast<int>(mesh.vertices.size());
  for (const auto& v : mesh.vertices) {
    if (!v.allFinite()) return fail(ErrorCode::kInvalidInput, "mesh: non-finite vertex");
  }
  for (const auto& t : mesh.triangles) {
    for (int i : t) {
      if (i < 0 || i >= n) return fail(ErrorCode::kInvalidInput, "mesh: vertex index out of range");
    }
  }
  return {};
}

}  // namespace

Result<WarpMap> projectiveTextureMap(const SurfaceMesh& mesh, const Mat34& projector,
                                     const Mat34& viewer, cv::Size output_size) {
  if (auto ok = validate(mesh); !ok) return tl::unexpected(ok.error());
  if (!projector.allFinite() || !viewer.allFinite() || output_size.width <= 0 ||
      output_size.height <= 0) {
    return fail(ErrorCode::kInvalidInput, "projectiveTextureMap: non-finite matrix or empty size");
  }
  WarpMap map{cv::Mat(output_size, CV_32FC2, cv::Scalar(kOutside, kOutside))};
  cv::Mat depth(output_size, CV_64FC1, cv::Scalar(std::numeric_limits<double>::infinity()));
  for (const auto& tri : mesh.triangles) {
    std::array<Vec3, 3> X, m;
    bool in_front = true;
    for (int k = 0; k < 3; ++k) {
      X[k] = mesh.vertices[tri[k]];
      m[k] = projector * X[k].homogeneous();
      in_front = in_front && m[k].z() > 0;
    }
    if (!in_front) continue;
    const Vec2 p0 = m[0].hnormalized(), p1 = m[1].hnormalized(), p2 = m[2].hnormalized();
    rasterizeTriangle(p0, p1, p2, output_size.width, output_size.height,
                      [&](int x, int y, double b0, double b1, double b2) {
                        // Perspective-correct weights: screen barycentrics over depth.
                        const double q0 = b0 / m[0].z(), q1 = b1 / m[1].z(), q2 = b2 / m[2].z();
                        const double q = q0 + q1 + q2;
                        const double z = 1.0 / q;
                        double& zbuf = depth.at<double>(y, x);
                        if (!(z < zbuf)) return;
                        zbuf = z;
                        const Vec3 M = (q0 * X[0] + q1 * X[1] + q2 * X[2]) * z;
                        const Vec3 t = viewer * M.homogeneous();
                        auto& out = map.xy.at<cv::Vec2f>(y, x);
                        if (!(t.z() > 0)) {
                          out = cv::Vec2f(kOutside, kOutside);
                          return;
                        }
                        const double sx = t.x() / t.z(), sy = t.y() / t.z();
                        out = (std::abs(sx) > 1e6 || std::abs(sy) > 1e6)
                                  ? cv::Vec2f(kOutside, kOutside)
                                  : cv::Vec2f(float(sx), float(sy));
                      });
  }
  return map;
}

Result<Mat4> pixelProjectionWithDepth(const Mat34& projector, double near_w, double far_w) {
  if (!projector.allFinite() || !(near_w > 0) || !(far_w > near_w) || !std::isfinite(far_w)) {
    return fail(ErrorCode::kInvalidInput, "pixelProjectionWithDepth: need 0 < near < far");
  }
  // z_ndc = a + b / w: -1 at near, +1 at far (the usual perspective depth).
  const double a = (far_w + near_w) / (far_w - near_w);
  const double b = -2.0 * far_w * near_w / (far_w - near_w);
  Mat4 M;
  M.row(0) = projector.row(0);
  M.row(1) = projector.row(1);
  M.row(2) = a * projector.row(2);
  M(2, 3) += b;
  M.row(3) = projector.row(2);
  return M;
}

Result<std::array<double, 2>> depthRange(const SurfaceMesh& mesh, const Mat34& projector) {
  if (auto ok = validate(mesh); !ok) return tl::unexpected(ok.error());
  if (mesh.vertices.empty()) return fail(ErrorCode::kInvalidInput, "depthRange: empty mesh");
  std::array<double, 2> r{std::numeric_limits<double>::infinity(),
                          -std::numeric_limits<double>::infinity()};
  for (const auto& v : mesh.vertices) {
    const double w = projector.row(2).dot(v.homogeneous());
    r[0] = std::min(r[0], w);
    r[1] = std::max(r[1], w);
  }
  return r;
}

}  // namespace procam::render
