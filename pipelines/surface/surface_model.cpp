#include "surface/surface_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>
#include <utility>
#include <vector>

namespace procam::surface {
namespace {

class QuadMesher {
 public:
  QuadMesher(const SurfacePoints& p, const SurfaceOptions& o) : p_(p), o_(o) {}

  SurfaceMesh run() {
    int size = 1;
    while (size * 2 <= std::max(1, o_.max_quad_nodes)) size *= 2;
    for (int j = 0; j + 1 < p_.nodes_y; j += size)
      for (int i = 0; i + 1 < p_.nodes_x; i += size) cell(i, j, size);
    // Every cell's corners; then each cell meshed with the corners of the cells beside
    // it that lie on its border: a larger cell next to finer ones becomes a fan from its
    // centre through those nodes, so no T-junction leaves a crack for a ray to slip
    // through (two triangles per cell let 3 % of a curved wall's rays miss it).
    corner_.assign(static_cast<std::size_t>(p_.nodes_x) * p_.nodes_y, 0);
    for (const Cell& c : cells_) {
      for (int dj : {0, c.s})
        for (int di : {0, c.s}) corner_[index(c.i + di, c.j + dj)] = 1;
    }
    for (const Cell& c : cells_) emit(c);
    return std::move(mesh_);
  }

 private:
  const Vec3* node(int i, int j) const {
    if (i < 0 || j < 0 || i >= p_.nodes_x || j >= p_.nodes_y) return nullptr;
    const std::int32_t k = p_.index[static_cast<std::size_t>(j) * p_.nodes_x + i];
    return k < 0 ? nullptr : &p_.world[static_cast<std::size_t>(k)];
  }

  // A cell of s x s node intervals is one quad if every node inside it exists, lies
  // within the tolerance of the bilinear patch of its corners and no neighbouring
  // nodes are further apart than max_edge (a depth step).
  bool flat(int i0, int j0, int s) const {
    const Vec3 *a = node(i0, j0), *b = node(i0 + s, j0), *c = node(i0, j0 + s),
               *d = node(i0 + s, j0 + s);
    if (!a || !b || !c || !d) return false;
    for (int j = 0; j <= s; ++j)
      for (int i = 0; i <= s; ++i) {
        const Vec3* x = node(i0 + i, j0 + j);
        if (!x) return false;
        const Vec3* right = i < s ? node(i0 + i + 1, j0 + j) : nullptr;
        const Vec3* down = j < s ? node(i0 + i, j0 + j + 1) : nullptr;
        if ((i < s && !right) || (j < s && !down)) return false;
        if (right && (*right - *x).norm() > o_.max_edge) return false;
        if (down && (*down - *x).norm() > o_.max_edge) return false;
        if (s > 1) {
          const double fu = static_cast<double>(i) / s, fv = static_cast<double>(j) / s;
          const Vec3 patch = (1 - fv) * ((1 - fu) * *a + fu * *b) + fv * ((1 - fu) * *c + fu * *d);
          if ((patch - *x).norm() > o_.mesh_tolerance) return false;
        }
      }
    return true;
  }

  struct Cell {
    int i = 0, j = 0, s = 1;  // top-left node and size in node intervals
  };

  std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * p_.nodes_x + i; }

  void cell(int i0, int j0, int s) {
    if (i0 + 1 >= p_.nodes_x || j0 + 1 >= p_.nodes_y) return;
    const bool inside = i0 + s < p_.nodes_x && j0 + s < p_.nodes_y;
    if (inside && flat(i0, j0, s)) {
      cells_.push_back({i0, j0, s});
      return;
    }
    if (s == 1) return;  // a hole: undecoded node or depth step
    const int h = s / 2;
    cell(i0, j0, h);
    cell(i0 + h, j0, h);
    cell(i0, j0 + h, h);
    cell(i0 + h, j0 + h, h);
  }

  void emit(const Cell& c) {
    // The border clockwise on screen from the top-left corner, through every node a
    // neighbouring cell has as a corner.
    std::vector<int> ring;
    auto add = [&](int i, int j) {
      if (corner_[index(i, j)]) ring.push_back(vertex(i, j));
    };
    for (int k = 0; k < c.s; ++k) add(c.i + k, c.j);
    for (int k = 0; k < c.s; ++k) add(c.i + c.s, c.j + k);
    for (int k = c.s; k > 0; --k) add(c.i + k, c.j + c.s);
    for (int k = c.s; k > 0; --k) add(c.i, c.j + k);
    if (ring.size() == 4) {
      mesh_.faces.emplace_back(ring[0], ring[1], ring[2]);
      mesh_.faces.emplace_back(ring[0], ring[2], ring[3]);
      return;
    }
    const int centre = vertex(c.i + c.s / 2, c.j + c.s / 2);
    for (std::size_t k = 0; k < ring.size(); ++k) {
      mesh_.faces.emplace_back(centre, ring[k], ring[(k + 1) % ring.size()]);
    }
  }

  int vertex(int i, int j) {
    const std::size_t n = static_cast<std::size_t>(j) * p_.nodes_x + i;
    auto [it, inserted] = vertices_.try_emplace(n, static_cast<int>(mesh_.vertices.size()));
    if (inserted) {
      const auto k = static_cast<std::size_t>(p_.index[n]);
      mesh_.vertices.push_back(p_.world[k]);
      mesh_.projector.push_back(p_.projector[k]);
    }
    return it->second;
  }

  const SurfacePoints& p_;
  const SurfaceOptions& o_;
  SurfaceMesh mesh_;
  std::unordered_map<std::size_t, int> vertices_;
  std::vector<Cell> cells_;
  std::vector<std::uint8_t> corner_;  // per node: a corner of some cell
};

// Nodes lost between decoded ones (a decoding dropout, not a hole in the surface): a
// missing node whose two neighbours across it on a row or a column are both present and
// no depth step apart gets their midpoint (their mean when both pairs exist), twice over,
// so single nodes and small clusters close from their rims; larger holes stay. On a curved wall the
// midpoint is off the surface by the chord's sag, L^2 / 8R: 0.2 mm for 7 cm on a 3 m radius.
SurfacePoints fillDropouts(const SurfacePoints& points, const SurfaceOptions& o) {
  SurfacePoints out = points;
  for (int pass = 0; pass < 2; ++pass) {
    auto at = [&](int i, int j) -> const Vec3* {
      if (i < 0 || j < 0 || i >= out.nodes_x || j >= out.nodes_y) return nullptr;
      const std::int32_t k = out.index[static_cast<std::size_t>(j) * out.nodes_x + i];
      return k < 0 ? nullptr : &out.world[static_cast<std::size_t>(k)];
    };
    std::vector<std::pair<std::size_t, Vec3>> added;
    for (int j = 0; j < out.nodes_y; ++j) {
      for (int i = 0; i < out.nodes_x; ++i) {
        if (at(i, j)) continue;
        Vec3 sum = Vec3::Zero();
        int pairs = 0;
        for (const auto& [a, b] :
             {std::pair(at(i - 1, j), at(i + 1, j)), std::pair(at(i, j - 1), at(i, j + 1))}) {
          if (a && b && (*a - *b).norm() <= 2 * o.max_edge) {
            sum += 0.5 * (*a + *b);
            ++pairs;
          }
        }
        if (pairs > 0)
          added.emplace_back(static_cast<std::size_t>(j) * out.nodes_x + i, sum / pairs);
      }
    }
    for (const auto& [n, x] : added) {
      out.index[n] = static_cast<std::int32_t>(out.world.size());
      out.world.push_back(x);
      out.projector.emplace_back(static_cast<double>(n % out.nodes_x) * out.step,
                                 static_cast<double>(n / out.nodes_x) * out.step);
      if (!out.gap.empty()) out.gap.push_back(0);
    }
  }
  return out;
}

}  // namespace

SurfaceMesh meshInProjectorSpace(const SurfacePoints& points, const SurfaceOptions& options) {
  const SurfacePoints filled = fillDropouts(points, options);
  return QuadMesher(filled, options).run();
}

Result<SurfaceModel> buildSurface(const SurfacePoints& points, const SurfaceOptions& o) {
  if (points.world.size() < 3)
    return fail(ErrorCode::kTooFewPoints, "surface: fewer than 3 triangulated points");
  geom::RansacOptions ransac;
  ransac.threshold = o.plane_threshold;
  auto fit = geom::fitPlaneRansac(points.world, ransac);
  if (!fit) return tl::unexpected(fit.error());
  SurfaceModel m;
  m.plane = fit->plane;
  m.plane_rms = fit->rms;
  m.inlier_fraction = static_cast<double>(fit->inliers.size()) / points.world.size();
  m.planar = m.inlier_fraction >= o.planar_inlier_fraction;
  if (!m.planar) m.mesh = meshInProjectorSpace(points, o);
  return m;
}

std::string toPly(const SurfaceMesh& mesh) {
  std::string out;
  out.reserve(64 + mesh.vertices.size() * 60 + mesh.faces.size() * 24);
  char line[160];
  out += "ply\nformat ascii 1.0\ncomment procamd display surface, world frame, metres\n";
  out += "element vertex " + std::to_string(mesh.vertices.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  out += "property float u\nproperty float v\n";
  out += "element face " + std::to_string(mesh.faces.size()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& x = mesh.vertices[i];
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g %.6g %.6g\n", x.x(), x.y(), x.z(),
                  mesh.projector[i].x(), mesh.projector[i].y());
    out += line;
  }
  for (const auto& f : mesh.faces) {
    std::snprintf(line, sizeof line, "3 %d %d %d\n", f.x(), f.y(), f.z());
    out += line;
  }
  return out;
}

}  // namespace procam::surface
