#include "surface/stereo_points.hpp"

#include "geometry/triangulate.hpp"

namespace procam::surface {

namespace {

// An empty point set on a projector grid of `nodes` nodes.
SurfacePoints emptyOnGrid(int step, int nodes_x, int nodes_y, std::size_t nodes) {
  SurfacePoints p;
  p.step = step;
  p.nodes_x = nodes_x;
  p.nodes_y = nodes_y;
  p.index.assign(nodes, -1);
  return p;
}

void append(SurfacePoints& p, std::size_t node, const Vec3& world, const Vec2& projector,
            double gap) {
  p.index[node] = static_cast<std::int32_t>(p.world.size());
  p.world.push_back(world);
  p.projector.push_back(projector);
  p.gap.push_back(gap);
}

}  // namespace

Result<SurfacePoints> triangulateStereo(const geom::CameraModel& a, const ProjectorSamples& sa,
                                        const geom::CameraModel& b, const ProjectorSamples& sb,
                                        const TriangulateOptions& o) {
  if (sa.step != sb.step || sa.nodes_x != sb.nodes_x || sa.nodes_y != sb.nodes_y)
    return fail(ErrorCode::kInvalidInput, "stereo samples come from different projector grids");
  SurfacePoints p = emptyOnGrid(sa.step, sa.nodes_x, sa.nodes_y, sa.index.size());
  for (std::size_t n = 0; n < sa.index.size(); ++n) {
    const std::int32_t ia = sa.index[n], ib = sb.index[n];
    if (ia < 0 || ib < 0) continue;
    auto ra = a.backproject(sa.camera[static_cast<std::size_t>(ia)]);
    auto rb = b.backproject(sb.camera[static_cast<std::size_t>(ib)]);
    if (!ra || !rb) continue;
    auto x = geom::triangulateRays(*ra, *rb);
    if (!x || x->t1 <= 0 || x->t2 <= 0 || x->gap > o.max_gap) continue;
    append(p, n, x->point, sa.projector[static_cast<std::size_t>(ia)], x->gap);
  }
  if (p.world.empty())
    return fail(ErrorCode::kTooFewPoints,
                "no projector pixel was seen in both views (check overlap and exposure)");
  return p;
}

SurfacePoints keepPoints(const SurfacePoints& points, const std::vector<std::uint8_t>& keep) {
  SurfacePoints out = emptyOnGrid(points.step, points.nodes_x, points.nodes_y, points.index.size());
  for (std::size_t n = 0; n < points.index.size(); ++n) {
    const std::int32_t k = points.index[n];
    if (k < 0 || static_cast<std::size_t>(k) >= keep.size() || !keep[static_cast<std::size_t>(k)])
      continue;
    const auto i = static_cast<std::size_t>(k);
    append(out, n, points.world[i], points.projector[i], points.gap[i]);
  }
  return out;
}

}  // namespace procam::surface
