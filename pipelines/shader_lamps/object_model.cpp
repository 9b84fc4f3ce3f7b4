#include "shader_lamps/object_model.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/units.hpp"

namespace procam::lamps {

namespace {

// Barycentric weights of p in triangle (a, b, c), p on its plane.
Vec3 barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const Vec3 e0 = b - a, e1 = c - a, d = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  const double v = (d11 * d20 - d01 * d21) / den;
  const double w = (d00 * d21 - d01 * d20) / den;
  return {1 - v - w, v, w};
}

// A canonical index per vertex position: a textured mesh repeats a vertex along each
// seam of its texture (one copy per side), and normals must be averaged across the seam
// as if it were one vertex. Positions within `tolerance` of each other share an index.
std::vector<std::uint32_t> weldedIndices(const std::vector<Vec3>& vertices, double tolerance) {
  const std::size_t n = vertices.size();
  std::vector<std::uint32_t> order(n), canonical(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return vertices[a].x() < vertices[b].x(); });
  for (std::size_t i = 0; i < n; ++i) canonical[i] = static_cast<std::uint32_t>(i);
  // Sweep along x: only vertices within the tolerance in x can coincide.
  for (std::size_t a = 0; a < n; ++a) {
    const std::uint32_t va = order[a];
    if (canonical[va] != va) continue;  // already welded to an earlier one
    for (std::size_t b = a + 1; b < n; ++b) {
      const std::uint32_t vb = order[b];
      if (vertices[vb].x() - vertices[va].x() > tolerance) break;
      if (canonical[vb] == vb && (vertices[vb] - vertices[va]).norm() <= tolerance)
        canonical[vb] = va;
    }
  }
  return canonical;
}

}  // namespace

Result<ObjectModel> ObjectModel::build(geom::TriangleMesh mesh, std::vector<Vec2> texcoords,
                                       double crease_deg) {
  if (mesh.faces.empty()) return fail(ErrorCode::kInvalidInput, "the object mesh has no faces");
  if (mesh.faces.size() > kMaxFaces)
    return fail(ErrorCode::kInvalidInput, "the object mesh has " +
                                              std::to_string(mesh.faces.size()) + " faces, over " +
                                              std::to_string(kMaxFaces));
  if (!texcoords.empty() && texcoords.size() != mesh.vertices.size())
    return fail(ErrorCode::kInvalidInput,
                "texture coordinates: " + std::to_string(texcoords.size()) + " for " +
                    std::to_string(mesh.vertices.size()) + " vertices");
  for (const Vec2& t : texcoords)
    if (!t.allFinite()) return fail(ErrorCode::kInvalidInput, "a texture coordinate is not finite");
  if (!(crease_deg >= 0 && crease_deg <= 180))
    return fail(ErrorCode::kInvalidInput, "the crease angle must lie in [0, 180] degrees");
  const std::size_t nv = mesh.vertices.size(), nf = mesh.faces.size();
  // Face normals and areas, after the intersector has checked indices and values.
  auto intersector = geom::MeshIntersector::build(std::move(mesh));
  if (!intersector) return tl::unexpected(intersector.error());
  ObjectModel out(std::move(*intersector));
  const geom::TriangleMesh& m = out.mesh();
  std::vector<Vec3> face_normals(nf);
  out.areas_.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = m.faces[f];
    const Vec3 cross =
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    const double n = cross.norm();
    if (!(n > 0)) return fail(ErrorCode::kDegenerate, "face " + std::to_string(f) + " has no area");
    face_normals[f] = cross / n;
    out.areas_[f] = 0.5 * n;
  }
  // Faces around each (welded) vertex, as compressed rows.
  Vec3 lo = m.vertices.front(), hi = lo;
  for (const Vec3& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const std::vector<std::uint32_t> weld = weldedIndices(m.vertices, 1e-9 * (hi - lo).norm());
  const auto vertexOf = [&](std::size_t f, int k) {
    return static_cast<std::size_t>(weld[static_cast<std::size_t>(m.faces[f][k])]);
  };
  std::vector<std::uint32_t> start(nv + 1, 0), around(3 * nf);
  for (std::size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) ++start[vertexOf(f, k) + 1];
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) around[fill[vertexOf(f, k)]++] = static_cast<std::uint32_t>(f);
  const double cos_crease = std::cos(degToRad(crease_deg));
  out.corner_normals_.resize(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = vertexOf(f, k);
      Vec3 sum = Vec3::Zero();
      for (std::uint32_t i = start[v]; i < start[v + 1]; ++i) {
        const std::uint32_t g = around[i];
        if (face_normals[g].dot(face_normals[f]) >= cos_crease)
          sum += out.areas_[g] * face_normals[g];
      }
      const double n = sum.norm();
      out.corner_normals_[3 * f + static_cast<std::size_t>(k)] =
          n > 0 ? Vec3(sum / n) : face_normals[f];
    }
  }
  out.texcoords_ = std::move(texcoords);
  return out;
}

SurfacePoint ObjectModel::at(std::uint32_t face, const Vec3& w) const {
  const geom::TriangleMesh& m = mesh();
  const auto& t = m.faces[face];
  SurfacePoint s;
  s.face = face;
  s.point = w[0] * m.vertices[t[0]] + w[1] * m.vertices[t[1]] + w[2] * m.vertices[t[2]];
  const std::size_t c = 3 * static_cast<std::size_t>(face);
  const Vec3 n =
      w[0] * corner_normals_[c] + w[1] * corner_normals_[c + 1] + w[2] * corner_normals_[c + 2];
  s.normal = n.norm() > 0 ? Vec3(n.normalized()) : corner_normals_[c];
  if (!texcoords_.empty())
    s.texcoord = w[0] * texcoords_[t[0]] + w[1] * texcoords_[t[1]] + w[2] * texcoords_[t[2]];
  return s;
}

std::optional<SurfacePoint> ObjectModel::intersect(const geom::Ray& ray,
                                                   geom::RayRange range) const {
  const auto hit = intersector_.intersect(ray, range);
  if (!hit) return std::nullopt;
  const geom::TriangleMesh& m = mesh();
  const auto& t = m.faces[hit->primitive];
  Vec3 w = barycentric(m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]], hit->point);
  w = w.cwiseMax(0.0);
  w /= w.sum();
  SurfacePoint s = at(hit->primitive, w);
  s.point = hit->point;
  // The side the ray sees: hit.normal faces the ray; keep the shading normal on it.
  if (s.normal.dot(hit->normal) < 0) s.normal = -s.normal;
  return s;
}

}  // namespace procam::lamps
