#include "shader_lamps/object_model.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "core/units.hpp"

namespace procam::lamps {

namespace {

// Barycentric weights of p in triangle (a, b, c), p on its plane.
Vec3 barycentric(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const Vec3 e0 = b - a, e1 = c - a, d = p - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0)) return Vec3::Constant(1.0 / 3);  // a sliver: its centre will do
  const double v = (d11 * d20 - d01 * d21) / den;
  const double w = (d00 * d21 - d01 * d20) / den;
  return {1 - v - w, v, w};
}

// A canonical index per vertex position: a textured mesh repeats a vertex along each
// seam of its texture (one copy per side), and normals must be averaged across the seam
// as if it were one vertex. Positions within `tolerance` of each other (per coordinate)
// share an index: each position is hashed by its cell of that size and compared with
// the vertices of the 27 cells around it, so the work stays linear in the vertices.
std::vector<std::uint32_t> weldedIndices(const std::vector<Vec3>& vertices, double tolerance) {
  const std::size_t n = vertices.size();
  std::vector<std::uint32_t> canonical(n);
  const double cell = std::max(tolerance, 1e-300);
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
           static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4Full ^
           static_cast<std::uint64_t>(z) * 0x165667B19E3779F9ull;
  };
  std::unordered_multimap<std::uint64_t, std::uint32_t> cells;
  cells.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 q = (vertices[i] / cell).array().floor().cwiseMax(-1e15).cwiseMin(1e15);
    const auto cx = static_cast<std::int64_t>(q.x()), cy = static_cast<std::int64_t>(q.y()),
               cz = static_cast<std::int64_t>(q.z());
    canonical[i] = static_cast<std::uint32_t>(i);
    bool found = false;
    for (int dz = -1; dz <= 1 && !found; ++dz) {
      for (int dy = -1; dy <= 1 && !found; ++dy) {
        for (int dx = -1; dx <= 1 && !found; ++dx) {
          const auto range = cells.equal_range(key(cx + dx, cy + dy, cz + dz));
          for (auto it = range.first; it != range.second; ++it) {
            if ((vertices[it->second] - vertices[i]).cwiseAbs().maxCoeff() <= tolerance) {
              canonical[i] = it->second;
              found = true;
              break;
            }
          }
        }
      }
    }
    if (!found) cells.emplace(key(cx, cy, cz), static_cast<std::uint32_t>(i));
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
