#include "content/mesh_placement.hpp"

#include <algorithm>
#include <cmath>

#include "render/gl_conventions.hpp"

namespace procam::content {

Result<PlacedMesh> placeMeshContent(const MeshContent& content, const PlanarView& view) {
  if (view.size.width < 2 || view.size.height < 2 || !view.projector.allFinite() ||
      !view.eye.allFinite() || !(view.plane_normal.norm() > 0)) {
    return fail(ErrorCode::kInvalidInput, "mesh placement: bad projector, plane or viewer");
  }
  Vec3 n = view.plane_normal.normalized();
  const double side = n.dot(view.eye - view.plane_point);
  if (std::abs(side) < 1e-3)
    return fail(ErrorCode::kDegenerate, "the viewer is on the display plane");
  if (side < 0) n = -n;
  Vec3 v = Vec3::UnitZ() - Vec3::UnitZ().dot(n) * n;
  if (v.norm() < 1e-6) v = Vec3::UnitY() - Vec3::UnitY().dot(n) * n;
  v.normalize();
  const Vec3 u = v.cross(n);  // u x v = n: the viewer is on the side of u x v
  const int W = view.size.width, H = view.size.height;
  auto S = keystone::boundingDisplayRect(view.projector, W, H, view.plane_point, u, v);
  if (!S) return tl::unexpected(S.error());
  const Vec3 centre = S->center();
  const double distance = n.dot(view.eye - centre);
  auto planar3d = planar3dForViewer(view, *S);
  if (!planar3d) return tl::unexpected(planar3d.error());
  PlacedMesh out;
  out.S = *S;
  out.planar3d = *planar3d;

  const Vec3 extent = content.max - content.min;
  double scale = 0.5 * std::min(S->width, S->height) / std::max({extent.x(), extent.y(), 1e-12});
  if (extent.z() > 0) scale = std::min(scale, 0.25 * distance / extent.z());
  const Vec3 mid = 0.5 * (content.min + content.max);
  auto place = [&](const Vec3& p) {
    return Vec3(centre + scale * ((p.x() - mid.x()) * u + (p.y() - mid.y()) * v +
                                  (p.z() - content.min.z()) * n));
  };
  const Vec3 light = (-0.3 * u + 0.5 * v + 0.8 * n).normalized();
  const auto& mesh = content.mesh;
  for (const auto& f : mesh.faces) {
    const Vec3 a = place(mesh.vertices[static_cast<size_t>(f[0])]);
    const Vec3 b = place(mesh.vertices[static_cast<size_t>(f[1])]);
    const Vec3 c = place(mesh.vertices[static_cast<size_t>(f[2])]);
    const Vec3 normal = (b - a).cross(c - a);
    if (!(normal.norm() > 0)) continue;  // degenerate face: nothing to draw
    const double intensity =
        kMeshAmbient + (1 - kMeshAmbient) * std::abs(normal.normalized().dot(light));
    const auto grey = static_cast<uint8_t>(std::lround(255 * intensity));
    const int base = static_cast<int>(out.mesh.vertices.size());
    for (const Vec3& p : {a, b, c}) {
      out.mesh.vertices.push_back(p);
      out.mesh.colors.emplace_back(grey, grey, grey, 255);
    }
    out.mesh.triangles.push_back({base, base + 1, base + 2});
  }
  if (out.mesh.triangles.empty()) {
    return fail(ErrorCode::kInvalidInput, "mesh placement: every face is degenerate");
  }
  return out;
}

Result<Mat4> planar3dForViewer(const PlanarView& view, const keystone::DisplayRect& S) {
  if (!view.eye.allFinite()) return fail(ErrorCode::kInvalidInput, "the viewer is not finite");
  const double distance = S.u.cross(S.v).dot(view.eye - S.center());
  if (!(distance > 1e-3))
    return fail(ErrorCode::kDegenerate, "the viewer is not in front of the display plane");
  // Depth range of P_T around the object: it lies between 0.75 and 1 times the plane
  // distance from the viewer.
  const int W = view.size.width, H = view.size.height;
  auto path =
      keystone::headTrackedPath(view.eye, S, 0.1 * distance, 2.0 * distance, view.projector, W, H);
  if (!path) return tl::unexpected(path.error());
  // Keystone's projector NDC has y up with image row 0 at the top.
  const Mat4 clip_top = render::glConventions(W, H, render::GlOrigin::kRow0AtGlTop).clip_from_pixel;
  return Mat4(clip_top.inverse() * path->single_pass);
}

}  // namespace procam::content
