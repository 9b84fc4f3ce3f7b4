#include "surface/stereo_points.hpp"

#include "geometry/triangulate.hpp"

namespace procam::surface {

Result<SurfacePoints> triangulateStereo(const geom::CameraModel& a, const ProjectorSamples& sa,
                                        const geom::CameraModel& b, const ProjectorSamples& sb,
                                        const TriangulateOptions& o) {
  if (sa.step != sb.step || sa.nodes_x != sb.nodes_x || sa.nodes_y != sb.nodes_y)
    return fail(ErrorCode::kInvalidInput, "stereo samples come from different projector grids");
  SurfacePoints p;
  p.step = sa.step;
  p.nodes_x = sa.nodes_x;
  p.nodes_y = sa.nodes_y;
  p.index.assign(sa.index.size(), -1);
  for (std::size_t n = 0; n < sa.index.size(); ++n) {
    const std::int32_t ia = sa.index[n], ib = sb.index[n];
    if (ia < 0 || ib < 0) continue;
    auto ra = a.backproject(sa.camera[static_cast<std::size_t>(ia)]);
    auto rb = b.backproject(sb.camera[static_cast<std::size_t>(ib)]);
    if (!ra || !rb) continue;
    auto x = geom::triangulateRays(*ra, *rb);
    if (!x || x->t1 <= 0 || x->t2 <= 0 || x->gap > o.max_gap) continue;
    p.index[n] = static_cast<std::int32_t>(p.world.size());
    p.world.push_back(x->point);
    p.projector.push_back(sa.projector[static_cast<std::size_t>(ia)]);
    p.gap.push_back(x->gap);
  }
  if (p.world.empty())
    return fail(ErrorCode::kTooFewPoints,
                "no projector pixel was decoded by both cameras (check overlap and exposure)");
  return p;
}

SurfacePoints keepPoints(const SurfacePoints& points, const std::vector<std::uint8_t>& keep) {
  SurfacePoints out;
  out.step = points.step;
  out.nodes_x = points.nodes_x;
  out.nodes_y = points.nodes_y;
  out.index.assign(points.index.size(), -1);
  for (std::size_t n = 0; n < points.index.size(); ++n) {
    const std::int32_t k = points.index[n];
    if (k < 0 || static_cast<std::size_t>(k) >= keep.size() || !keep[static_cast<std::size_t>(k)])
      continue;
    out.index[n] = static_cast<std::int32_t>(out.world.size());
    out.world.push_back(points.world[static_cast<std::size_t>(k)]);
    out.projector.push_back(points.projector[static_cast<std::size_t>(k)]);
    out.gap.push_back(points.gap[static_cast<std::size_t>(k)]);
  }
  return out;
}

}  // namespace procam::surface
