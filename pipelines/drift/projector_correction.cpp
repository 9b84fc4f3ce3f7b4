#include "projector_correction.hpp"

#include <cmath>
#include <vector>

#include "geometry/intersect.hpp"
#include "pose_refit.hpp"

namespace procam::drift {

namespace {

struct RegisteredTiles {
  std::vector<Vec2> drawn, seen;
};

// The inlier tiles, refused when too few or not finite.
Result<RegisteredTiles> registeredTiles(const Misregistration& drift) {
  RegisteredTiles out;
  for (const TileShift& t : drift.tiles) {
    if (!t.inlier) continue;
    if (!t.drawn.allFinite() || !t.seen_at.allFinite()) {
      return fail(ErrorCode::kInvalidInput, "drift correction: a tile is not finite");
    }
    out.drawn.push_back(t.drawn);
    out.seen.push_back(t.seen_at);
  }
  if (static_cast<int>(out.drawn.size()) < kMinCorrectionTiles) {
    return fail(ErrorCode::kTooFewPoints, "drift correction: " + std::to_string(out.drawn.size()) +
                                              " registered tiles, at least " +
                                              std::to_string(kMinCorrectionTiles) + " needed");
  }
  return out;
}

// The pose refitted to the tiles' surface points, refused when it fits them worse than
// a rigid projector would.
Result<PoseRefit> refitToTiles(const geom::CameraModel& model, const std::vector<Vec3>& world,
                               const std::vector<Vec2>& drawn) {
  auto pose = refitPose(model, world, drawn);
  if (!pose) return tl::unexpected(pose.error());
  // The tiles scatter by about 0.2 px about one collineation: a pose that fits them far
  // worse is not a moved projector (a moved surface, a bad match).
  if (pose->rms_px > kMaxRefitRmsPx) {
    return fail(ErrorCode::kIllConditioned, "drift correction: the new pose fits the tiles to " +
                                                std::to_string(pose->rms_px) + " px RMS (at most " +
                                                std::to_string(kMaxRefitRmsPx) + ")");
  }
  return pose;
}

}  // namespace

Result<ProjectorCorrection> correctProjector(const rig::RigProjector& before,
                                             const geom::PlaneHomography& tile,
                                             const Misregistration& drift) {
  auto tiles = registeredTiles(drift);
  if (!tiles) return tl::unexpected(tiles.error());
  const std::vector<Vec2>& drawn = tiles->drawn;
  const std::vector<Vec2>& seen = tiles->seen;
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
    auto pose = refitToTiles(model, world, drawn);
    if (!pose) return tl::unexpected(pose.error());
    out.projector.pose = pose->pose;
    out.pose_rms_px = pose->rms_px;
  }
  return out;
}

Result<ProjectorCorrection> correctProjector(const rig::RigProjector& before,
                                             const LitSurface& surface,
                                             const Misregistration& drift) {
  if (!before.pose_known || !before.intrinsics_known) {
    return fail(ErrorCode::kInvalidInput,
                "drift correction: on a curved surface the projector's pose and intrinsics are "
                "needed");
  }
  if (!surface.point) return fail(ErrorCode::kInvalidInput, "drift correction: no surface");
  auto tiles = registeredTiles(drift);
  if (!tiles) return tl::unexpected(tiles.error());
  // The pose is fitted in the model the points come from: the pinhole, to the pinhole
  // pixels the drawn pixels show, when a warp stands for the lens.
  geom::CameraModel model = before.model();
  if (surface.to_pinhole) model.dist = {};
  std::vector<Vec3> world;
  std::vector<Vec2> drawn;
  for (std::size_t i = 0; i < tiles->seen.size(); ++i) {
    // A tile seen where the surface has a hole (a measured mesh's) tells nothing.
    const auto point = surface.point(tiles->seen[i]);
    if (!point || !point->allFinite()) continue;
    world.push_back(*point);
    drawn.push_back(surface.to_pinhole ? surface.to_pinhole(tiles->drawn[i]) : tiles->drawn[i]);
  }
  if (static_cast<int>(world.size()) < kMinCorrectionTiles) {
    return fail(ErrorCode::kTooFewPoints, "drift correction: " + std::to_string(world.size()) +
                                              " tiles light the surface, at least " +
                                              std::to_string(kMinCorrectionTiles) + " needed");
  }
  auto pose = refitToTiles(model, world, drawn);
  if (!pose) return tl::unexpected(pose.error());
  ProjectorCorrection out;
  out.projector = before;
  out.tiles = static_cast<int>(world.size());
  out.fit_rms_px = drift.tile_rms_px;
  out.drawn_to_seen = drift.drawn_to_seen;
  out.projector.pose = pose->pose;
  out.pose_rms_px = pose->rms_px;
  return out;
}

}  // namespace procam::drift
