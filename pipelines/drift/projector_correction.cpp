#include "projector_correction.hpp"

#include <cmath>
#include <vector>

#include "geometry/intersect.hpp"
#include "pose_refit.hpp"

namespace procam::drift {

Result<ProjectorCorrection> correctProjector(const rig::RigProjector& before,
                                             const geom::PlaneHomography& tile,
                                             const Misregistration& drift) {
  std::vector<Vec2> drawn, seen;
  for (const TileShift& t : drift.tiles) {
    if (!t.inlier) continue;
    if (!t.drawn.allFinite() || !t.seen_at.allFinite()) {
      return fail(ErrorCode::kInvalidInput, "drift correction: a tile is not finite");
    }
    drawn.push_back(t.drawn);
    seen.push_back(t.seen_at);
  }
  if (static_cast<int>(drawn.size()) < kMinCorrectionTiles) {
    return fail(ErrorCode::kTooFewPoints, "drift correction: " + std::to_string(drawn.size()) +
                                              " registered tiles, at least " +
                                              std::to_string(kMinCorrectionTiles) + " needed");
  }
  if (!drift.drawn_to_seen.allFinite() || !(std::abs(drift.drawn_to_seen(2, 2)) > 0)) {
    return fail(ErrorCode::kInvalidInput, "drift correction: the shift field is not finite");
  }
  ProjectorCorrection out;
  out.projector = before;
  out.tiles = static_cast<int>(drawn.size());
  out.fit_rms_px = drift.tile_rms_px;
  out.drawn_to_seen = drift.drawn_to_seen;
  // Framebuffer -> plane: through T, then the collineation the rig had.
  if (before.plane_homography) {
    geom::PlaneHomography ph = *before.plane_homography;
    // The rig's own collineation and `tile`'s are the same mapping here; T applies on
    // the framebuffer side, so the basis stays.
    ph.H = before.plane_homography->H * out.drawn_to_seen;
    ph.H /= ph.H.norm();
    out.projector.plane_homography = ph;
  }
  if (before.pose_known && before.intrinsics_known) {
    // The wall points by the projector's own model (its lens distortion included, as the
    // PnP below models it), on the display plane.
    const geom::CameraModel model = before.model();
    const Vec3 n = tile.basis.normal().normalized();
    const geom::Plane plane{n, -n.dot(tile.basis.origin)};
    std::vector<Vec3> world;
    for (const Vec2& s : seen) {
      auto ray = model.backproject(s);
      auto hit = ray ? geom::intersectPlane(*ray, plane) : std::nullopt;
      if (!hit) {
        return fail(ErrorCode::kDegenerate, "drift correction: a tile's ray misses the plane");
      }
      world.push_back(hit->point);
    }
    auto pose = refitPose(model, world, drawn);
    if (!pose) return tl::unexpected(pose.error());
    // The tiles scatter by about 0.2 px about one collineation: a pose that fits them far
    // worse is not a moved projector (a non-planar surface moved, a bad match).
    if (pose->rms_px > kMaxRefitRmsPx) {
      return fail(ErrorCode::kIllConditioned, "drift correction: the new pose fits the tiles to " +
                                                  std::to_string(pose->rms_px) +
                                                  " px RMS (at most " +
                                                  std::to_string(kMaxRefitRmsPx) + ")");
    }
    out.projector.pose = pose->pose;
    out.pose_rms_px = pose->rms_px;
  }
  return out;
}

}  // namespace procam::drift
