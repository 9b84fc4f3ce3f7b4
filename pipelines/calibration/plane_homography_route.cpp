#include "calibration/plane_homography_route.hpp"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "geometry/homography.hpp"
#include "surface/projector_samples.hpp"

namespace procam::calib {

namespace {

std::vector<cv::Point2d> cvPoints(const Points2& p) {
  std::vector<cv::Point2d> out;
  out.reserve(p.size());
  for (const Vec2& q : p) out.emplace_back(q.x(), q.y());
  return out;
}

}  // namespace

double coverageOf(const Points2& points, int w, int h) {
  if (points.size() < 3 || w <= 0 || h <= 0) return 0;
  std::vector<cv::Point2f> pts;
  pts.reserve(points.size());
  for (const Vec2& p : points)
    pts.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  std::vector<cv::Point2f> hull;
  cv::convexHull(pts, hull);
  return hull.size() < 3 ? 0.0 : cv::contourArea(hull) / (double(w) * double(h));
}

Result<CollineationNodes> collineationNodes(const sl::PatternSet& set, const DecodedView& view,
                                            const PlaneHomographyOptions& o) {
  const geom::CameraModel& camera = view.camera;
  if (view.decoded.u.cols != camera.width || view.decoded.u.rows != camera.height)
    return fail(ErrorCode::kInvalidInput,
                "captures of camera '" + view.name + "' are " +
                    std::to_string(view.decoded.u.cols) + "x" +
                    std::to_string(view.decoded.u.rows) + " but its calibration is " +
                    std::to_string(camera.width) + "x" + std::to_string(camera.height));
  const int pw = set.options.width, ph = set.options.height;

  // Projector nodes and the camera pixels that see them ([Raskar02] §4.1.1), the
  // camera's lens distortion removed: collineations hold between pinhole images.
  auto samples = surface::sampleProjectorGrid(view.decoded, pw, ph,
                                              {.step = o.step, .radius = sampleRadius(set)});
  if (!samples) return tl::unexpected(samples.error());
  return collineationOfPoints(samples->projector, samples->camera, camera, view.name, o);
}

Result<CollineationNodes> collineationOfPoints(const Points2& projector, const Points2& seen_px,
                                               const geom::CameraModel& camera,
                                               const std::string& name,
                                               const PlaneHomographyOptions& o) {
  if (projector.size() != seen_px.size()) {
    return fail(ErrorCode::kInvalidInput, "projector and camera points differ in number");
  }
  Points2 proj, cam;
  for (std::size_t i = 0; i < seen_px.size(); ++i) {
    const Vec2& seen = seen_px[i];
    if (!seen.allFinite() || !projector[i].allFinite()) {
      return fail(ErrorCode::kInvalidInput, "a point seen by camera '" + name + "' is not finite");
    }
    const double m = o.edge_margin_px;
    if (seen.x() < m || seen.y() < m || seen.x() > camera.width - 1 - m ||
        seen.y() > camera.height - 1 - m)
      continue;
    auto ideal = camera.undistortPixel(seen);
    if (!ideal) continue;
    proj.push_back(projector[i]);
    cam.push_back(*ideal);
  }
  CollineationNodes out;
  out.samples = proj.size();
  // A collineation needs four points (and OpenCV's RANSAC refuses fewer).
  const std::size_t min_points = std::max<std::size_t>(o.min_points, 4);
  if (proj.size() < min_points)
    return fail(ErrorCode::kTooFewPoints,
                "camera '" + name + "' saw only " + std::to_string(proj.size()) +
                    " projector nodes (need " + std::to_string(min_points) + ")");

  // Robust support (RANSAC); the caller fits the inliers alone.
  std::vector<unsigned char> mask;
  const cv::Mat H0 = cv::findHomography(cvPoints(proj), cvPoints(cam), cv::RANSAC,
                                        o.ransac_threshold_px, mask, 2000, 0.999);
  if (H0.empty())
    return fail(ErrorCode::kDegenerate,
                "camera '" + name + "': no collineation fits the projector nodes it saw");
  for (std::size_t i = 0; i < proj.size(); ++i) {
    if (!mask[i]) continue;
    out.projector.push_back(proj[i]);
    out.camera.push_back(cam[i]);
  }
  if (out.projector.size() < min_points)
    return fail(ErrorCode::kTooFewPoints,
                "only " + std::to_string(out.projector.size()) + " of " +
                    std::to_string(proj.size()) + " projector nodes fit one collineation (need " +
                    std::to_string(min_points) + "): is the surface planar?");
  return out;
}

Result<geom::PlaneHomography> planeFromCamera(const geom::CameraModel& camera,
                                              const geom::Plane& plane, const Points2& seen,
                                              const std::string& name) {
  // The plane in the upright basis seen from the camera, centred where the camera
  // saw the projection; the camera's rays through `seen` must reach it in front.
  const Vec3 centre = camera.pose.center();
  auto basis = geom::uprightBasis(plane, centre, centre);
  if (!basis) return tl::unexpected(basis.error());
  auto plane_to_camera = geom::planeToImage(camera.K, camera.pose, *basis);
  if (!plane_to_camera) return tl::unexpected(plane_to_camera.error());
  const Mat3 camera_to_plane = plane_to_camera->inverse();
  Vec2 mean = Vec2::Zero();
  const Mat3 Kinv = camera.K.matrix().inverse();
  for (const Vec2& c : seen) {
    const Vec3 dir = camera.pose.R.transpose() * (Kinv * c.homogeneous());
    const double along = plane.n.dot(dir);
    const double t = std::abs(along) > 1e-12 ? -plane.signedDistance(centre) / along : -1.0;
    if (!(t > 0))
      return fail(ErrorCode::kDegenerate,
                  "camera '" + name +
                      "' sees the projection where the given plane is not in front of it: "
                      "the plane is not the lit surface");
    mean += (camera_to_plane * c.homogeneous()).hnormalized();
  }
  if (!seen.empty()) mean /= double(seen.size());
  basis->origin = basis->toWorld(mean);
  Mat3 shift = Mat3::Identity();
  shift.topRightCorner<2, 1>() = -mean;
  return geom::PlaneHomography{*basis, shift * camera_to_plane};
}

Result<PlaneHomographyResult> solvePlaneHomographyRoute(const sl::PatternSet& set,
                                                        const DecodedView& view,
                                                        const geom::Plane& plane_in,
                                                        const PlaneHomographyOptions& o) {
  const geom::CameraModel& camera = view.camera;
  const double n_norm = plane_in.n.norm();
  if (!plane_in.n.allFinite() || !std::isfinite(plane_in.d) || !(n_norm > 1e-9))
    return fail(ErrorCode::kInvalidInput, "the display plane must be finite with a normal");
  auto nodes = collineationNodes(set, view, o);
  if (!nodes) return tl::unexpected(nodes.error());
  return solvePlaneFromNodes(*nodes, camera, view.name, plane_in, set.options.width,
                             set.options.height, o);
}

Result<PlaneHomographyResult> solvePlaneFromNodes(const CollineationNodes& nodes,
                                                  const geom::CameraModel& camera,
                                                  const std::string& name,
                                                  const geom::Plane& plane_in, int pw, int ph,
                                                  const PlaneHomographyOptions& o) {
  const double n_norm = plane_in.n.norm();
  if (!plane_in.n.allFinite() || !std::isfinite(plane_in.d) || !(n_norm > 1e-9))
    return fail(ErrorCode::kInvalidInput, "the display plane must be finite with a normal");
  const geom::Plane plane{plane_in.n / n_norm, plane_in.d / n_norm};
  const Points2& proj_in = nodes.projector;
  const Points2& cam_in = nodes.camera;
  PlaneHomographyResult out;
  out.samples = nodes.samples;
  out.inliers = proj_in.size();
  out.coverage = coverageOf(proj_in, pw, ph);
  if (out.coverage < o.min_coverage)
    return fail(ErrorCode::kDegenerate,
                "camera '" + name + "' sees " + std::to_string(100 * out.coverage) +
                    " % of the projector's image; the collineation would be extrapolated "
                    "(aim the camera at the projection)");
  auto fit = geom::fitHomography(proj_in, cam_in);
  if (!fit) return tl::unexpected(fit.error());
  out.projector_to_camera = fit->H;
  out.rms_camera_px = fit->rms;
  out.condition = fit->condition;
  const Mat3 cam_to_proj = fit->H.inverse();
  double sum = 0;
  for (std::size_t i = 0; i < proj_in.size(); ++i) {
    const auto back = geom::applyHomography(cam_to_proj, cam_in[i]);
    if (!back) return fail(ErrorCode::kDegenerate, "the collineation is singular on its inliers");
    sum += (*back - proj_in[i]).squaredNorm();
  }
  out.rms_projector_px = std::sqrt(sum / double(proj_in.size()));

  auto on_plane = planeFromCamera(camera, plane, cam_in, name);
  if (!on_plane) return tl::unexpected(on_plane.error());
  Mat3 H = on_plane->H * fit->H;  // [Raskar02] §4.2.4: A_wp = A_wc^-1 A_cp
  H /= H.norm();
  if (H(2, 2) < 0) H = -H;
  if (!H.allFinite())
    return fail(ErrorCode::kIllConditioned, "the projector-to-plane collineation is not finite");
  out.projector_to_plane = {on_plane->basis, H};
  return out;
}

}  // namespace procam::calib
