#include "projector_correction.hpp"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

#include "geometry/intersect.hpp"

namespace procam::drift {
namespace {

constexpr int kMinTiles = 8;
constexpr double kMaxPoseRmsPx = 1.0;

// The camera pose of `before` refined to framebuffer pixels `px` of world points `world`
// (Levenberg-Marquardt from the old pose: a bump is small).
Result<std::pair<geom::Pose, double>> refinePose(const rig::RigProjector& before,
                                                 const std::vector<Vec3>& world,
                                                 const std::vector<Vec2>& px) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (std::size_t i = 0; i < world.size(); ++i) {
    object.emplace_back(world[i].x(), world[i].y(), world[i].z());
    image.emplace_back(px[i].x(), px[i].y());
  }
  cv::Mat K, dist = (cv::Mat_<double>(1, 5) << before.dist.k1, before.dist.k2, before.dist.p1,
                     before.dist.p2, before.dist.k3);
  cv::eigen2cv(Mat3(before.K.matrix()), K);
  cv::Mat R, rvec, tvec;
  cv::eigen2cv(Mat3(before.pose.R), R);
  cv::Rodrigues(R, rvec);
  cv::eigen2cv(Vec3(before.pose.t), tvec);
  if (!cv::solvePnP(object, image, K, dist, rvec, tvec, true, cv::SOLVEPNP_ITERATIVE)) {
    return fail(ErrorCode::kNoConvergence, "the projector's pose did not converge");
  }
  cv::Rodrigues(rvec, R);
  geom::Pose pose;
  cv::cv2eigen(R, pose.R);
  cv::cv2eigen(tvec, pose.t);
  if (!pose.R.allFinite() || !pose.t.allFinite()) {
    return fail(ErrorCode::kNoConvergence, "the projector's pose is not finite");
  }
  std::vector<cv::Point2d> back;
  cv::projectPoints(object, rvec, tvec, K, dist, back);
  double sq = 0;
  for (std::size_t i = 0; i < back.size(); ++i) {
    sq += std::pow(back[i].x - image[i].x, 2) + std::pow(back[i].y - image[i].y, 2);
  }
  return std::make_pair(pose, std::sqrt(sq / static_cast<double>(back.size())));
}

}  // namespace

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
  if (static_cast<int>(drawn.size()) < kMinTiles) {
    return fail(ErrorCode::kTooFewPoints, "drift correction: " + std::to_string(drawn.size()) +
                                              " registered tiles, at least " +
                                              std::to_string(kMinTiles) + " needed");
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
    auto pose = refinePose(before, world, drawn);
    if (!pose) return tl::unexpected(pose.error());
    // The tiles scatter by about 0.2 px about one collineation: a pose that fits them far
    // worse is not a moved projector (a non-planar surface moved, a bad match).
    if (pose->second > kMaxPoseRmsPx) {
      return fail(ErrorCode::kIllConditioned, "drift correction: the new pose fits the tiles to " +
                                                  std::to_string(pose->second) +
                                                  " px RMS (at most " +
                                                  std::to_string(kMaxPoseRmsPx) + ")");
    }
    out.projector.pose = pose->first;
    out.pose_rms_px = pose->second;
  }
  return out;
}

}  // namespace procam::drift
