#include "calibration/wall_views_route.hpp"

#include <cmath>
#include <string>

namespace procam::calib {

Result<WallSighting> wallSighting(const sl::PatternSet& set, const DecodedView& view,
                                  const PlaneHomographyOptions& options) {
  auto nodes = collineationNodes(set, view, options);
  if (!nodes && nodes.error().code == ErrorCode::kInvalidInput)
    return tl::unexpected(nodes.error());
  if (!nodes) return WallSighting{std::nullopt, nodes.error().message};
  return WallSighting{std::move(*nodes), {}};
}

Result<WallViewsResult> solveWallViews(std::span<const std::pair<int, int>> projector_sizes,
                                       std::size_t cameras, std::span<const WallNodes> nodes,
                                       const geom::CameraModel& reference,
                                       const std::string& reference_name,
                                       const geom::Plane& plane_in,
                                       const WallViewsOptions& options) {
  const double n_norm = plane_in.n.norm();
  if (!plane_in.n.allFinite() || !std::isfinite(plane_in.d) || !(n_norm > 1e-9))
    return fail(ErrorCode::kInvalidInput, "the display plane must be finite with a normal");
  const geom::Plane plane{plane_in.n / n_norm, plane_in.d / n_norm};
  if (options.reference_camera >= cameras)
    return fail(ErrorCode::kInvalidInput, "the reference camera is out of range");
  const std::size_t projectors = projector_sizes.size();
  // A collineation needs four points; the tree links no fewer.
  const std::size_t min_points = std::max<std::size_t>(options.nodes.min_points, 4);
  WallViewsResult out;
  out.projectors.resize(projectors);
  std::vector<Points2> seen_of(projectors);
  std::vector<geom::ViewProjectorMatches> matches;
  Points2 reference_seen;
  for (const WallNodes& n : nodes) {
    if (n.projector >= projectors || n.camera >= cameras)
      return fail(ErrorCode::kInvalidInput, "a sighting's projector or camera is out of range");
    if (n.nodes.projector.size() != n.nodes.camera.size())
      return fail(ErrorCode::kInvalidInput, "a sighting's node lists differ in length");
    if (n.nodes.projector.size() < min_points) continue;
    if (n.camera == options.reference_camera) {
      reference_seen.insert(reference_seen.end(), n.nodes.camera.begin(), n.nodes.camera.end());
    }
    Points2& seen = seen_of[n.projector];
    seen.insert(seen.end(), n.nodes.projector.begin(), n.nodes.projector.end());
    ++out.projectors[n.projector].cameras;
    out.projectors[n.projector].samples += n.nodes.samples;
    matches.push_back({n.camera, n.projector, n.nodes.projector, n.nodes.camera});
  }
  for (std::size_t p = 0; p < projectors; ++p) {
    auto& stats = out.projectors[p];
    stats.nodes = seen_of[p].size();
    stats.coverage = coverageOf(seen_of[p], projector_sizes[p].first, projector_sizes[p].second);
    if (stats.cameras > 0 && stats.coverage < options.nodes.min_coverage)
      return fail(ErrorCode::kDegenerate,
                  (p < options.projector_names.size() ? options.projector_names[p]
                                                      : "projector " + std::to_string(p)) +
                      ": the cameras see " + std::to_string(100 * stats.coverage) +
                      " % of its image; its collineation would be extrapolated");
  }
  auto tree = geom::solveHomographyTree(matches, cameras, projectors,
                                        {.reference_view = options.reference_camera,
                                         .min_matches = min_points,
                                         .view_names = options.camera_names,
                                         .projector_names = options.projector_names});
  if (!tree) return tl::unexpected(tree.error());
  // [Raskar02] §4.2.4: A_wp = A_wc^-1 A_cp, the reference camera's A_wc.
  auto on_plane = planeFromCamera(reference, plane, reference_seen, reference_name);
  if (!on_plane) return tl::unexpected(on_plane.error());
  for (const Mat3& P : tree->projector_to_reference) {
    Mat3 H = on_plane->H * P;
    H /= H.norm();
    if (H(2, 2) < 0) H = -H;
    if (!H.allFinite())
      return fail(ErrorCode::kIllConditioned, "a projector-to-plane collineation is not finite");
    out.projector_to_plane.push_back({on_plane->basis, H});
  }
  // Each projector's residual over the cameras that saw it.
  std::vector<double> sq(projectors, 0), sq_back(projectors, 0);
  for (const auto& m : matches) {
    const Mat3 M =
        tree->view_to_reference[m.view].inverse() * tree->projector_to_reference[m.projector];
    const Mat3 back = M.inverse();
    for (std::size_t i = 0; i < m.projector_px.size(); ++i) {
      sq[m.projector] +=
          ((M * m.projector_px[i].homogeneous()).hnormalized() - m.view_px[i]).squaredNorm();
      sq_back[m.projector] +=
          ((back * m.view_px[i].homogeneous()).hnormalized() - m.projector_px[i]).squaredNorm();
    }
  }
  for (std::size_t p = 0; p < projectors; ++p) {
    auto& stats = out.projectors[p];
    if (stats.nodes == 0) continue;
    stats.rms_px = std::sqrt(sq[p] / double(stats.nodes));
    stats.rms_projector_px = std::sqrt(sq_back[p] / double(stats.nodes));
  }
  out.tree = std::move(*tree);
  return out;
}

}  // namespace procam::calib
