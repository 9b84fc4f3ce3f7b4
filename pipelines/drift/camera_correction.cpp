#include "camera_correction.hpp"

#include <cmath>
#include <vector>

#include "pose_refit.hpp"

namespace procam::drift {
Result<CameraCorrection> correctCamera(const rig::RigCamera& before,
                                       const geom::PlaneHomography& tile,
                                       const Misregistration& drift, const cv::Mat& map,
                                       const WorkGrid& grid) {
  if (!tile.H.allFinite()) {
    return fail(ErrorCode::kInvalidInput, "camera correction: the collineation is not finite");
  }
  return correctCamera(before, planeLitSurface(tile, grid.framebuffer), drift, map, grid);
}

Result<CameraCorrection> correctCamera(const rig::RigCamera& before, const LitSurface& surface,
                                       const Misregistration& drift, const cv::Mat& map,
                                       const WorkGrid& grid) {
  if (!surface.point) return fail(ErrorCode::kInvalidInput, "camera correction: no surface");
  if (!before.pose_known) {
    return fail(ErrorCode::kInvalidInput, "camera correction: the camera has no pose to refine");
  }
  if (map.type() != CV_32FC2 || map.size() != grid.size()) {
    return fail(ErrorCode::kInvalidInput, "camera correction: the map is not the grid's");
  }
  std::vector<Vec3> world;
  std::vector<Vec2> pixels;
  for (const TileShift& t : drift.tiles) {
    if (!t.inlier) continue;
    if (!t.drawn.allFinite() || !t.seen_at.allFinite()) {
      return fail(ErrorCode::kInvalidInput, "camera correction: a tile is not finite");
    }
    const auto X = surface.point(t.drawn);
    if (!X || !X->allFinite()) continue;
    auto px = mappedCameraPixel(map, grid.toWork(t.seen_at));
    if (!px) continue;
    world.push_back(*X);
    pixels.push_back(*px);
  }
  if (static_cast<int>(world.size()) < kMinCorrectionTiles) {
    return fail(ErrorCode::kTooFewPoints, "camera correction: " + std::to_string(world.size()) +
                                              " registered tiles, at least " +
                                              std::to_string(kMinCorrectionTiles) + " needed");
  }
  auto pose = refitPose(before.model, world, pixels);
  if (!pose) return tl::unexpected(pose.error());
  if (pose->rms_px > kMaxRefitRmsPx) {
    return fail(ErrorCode::kIllConditioned, "camera correction: the new pose fits the tiles to " +
                                                std::to_string(pose->rms_px) +
                                                " camera px RMS (at most " +
                                                std::to_string(kMaxRefitRmsPx) + ")");
  }
  CameraCorrection out;
  out.camera = before;
  out.camera.model.pose = pose->pose;
  out.pose_rms_px = pose->rms_px;
  out.tiles = static_cast<int>(world.size());
  return out;
}

}  // namespace procam::drift
