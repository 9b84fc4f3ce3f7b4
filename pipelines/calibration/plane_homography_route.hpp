#pragma once
// Route (b′): a projector on a planar display surface from one calibrated camera and
// the plane's position in the world ([Raskar02] §4.2.1, §4.2.4: on a plane every
// pair of images is related by a collineation, and collineations chain). The
// decoded structured light gives projector pixel <-> camera pixel; their
// collineation A_cp is fitted robustly; the camera's model and the plane give the
// camera's collineation with the plane A_wc; their chain A_wc^-1 A_cp maps projector
// pixels to the plane. Neither the projector's intrinsics nor its pose are needed.
//
// The plane is what an installer gives (measured, or from fiducials of known size):
// one camera cannot measure the depth of a plane it sees, only its collineation.
#include <cstddef>
#include <string>

#include "calibration/stereo_route.hpp"
#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/plane_fit.hpp"
#include "geometry/plane_homography.hpp"
#include "structured_light/pattern_set.hpp"

namespace procam::calib {

struct PlaneHomographyOptions {
  int step = 8;  // projector pixels between sampled nodes
  // RANSAC inlier distance in camera pixels. A sampled node's camera position
  // averages a neighbourhood of decoded pixels and scatters by well under 0.2 px
  // under the reference capture conditions; a node this far off the collineation
  // is not on the plane (or was mis-decoded).
  double ransac_threshold_px = 1.0;
  std::size_t min_points = 20;  // inlier nodes
  // Nodes the camera sees this close to its image edge are left out: the camera's
  // blur and the node's neighbourhood of decoded pixels are cut there. On the virtual
  // rig a projector seen only along the edge of a camera's view came out with its far
  // corners 0.26 px off through them, 0.008 px without them.
  double edge_margin_px = 4;
  // Convex hull of the inlier nodes over the projector frame. Below this the
  // collineation is extrapolated far beyond what the camera saw.
  double min_coverage = 0.05;
};

struct PlaneHomographyResult {
  geom::PlaneHomography projector_to_plane;     // upright basis (geom::uprightBasis), lit side
  Mat3 projector_to_camera = Mat3::Identity();  // to ideal (undistorted) camera pixels
  double rms_camera_px = 0;                     // of the collineation fit, inliers, camera pixels
  double rms_projector_px = 0;                  // the same residuals transferred into the projector
  double condition = 0;     // of the Hartley-normalised DLT (geom::HomographyFit)
  double coverage = 0;      // inlier nodes' convex hull / projector frame area
  std::size_t samples = 0;  // projector nodes the camera saw
  std::size_t inliers = 0;
};

// The projector nodes (every options.step px) a camera saw and where (ideal, undistorted
// camera pixels), those that fit one collineation (RANSAC with
// options.ransac_threshold_px). kInvalidInput for a decoded map whose size is not its
// camera's; kTooFewPoints below options.min_points nodes or inliers; kDegenerate when
// no collineation fits.
struct CollineationNodes {
  Points2 projector, camera;  // inliers, one to one
  std::size_t samples = 0;    // nodes seen, before RANSAC
};
Result<CollineationNodes> collineationNodes(const sl::PatternSet& set, const DecodedView& view,
                                            const PlaneHomographyOptions& options = {});

// The same from points found otherwise (a fiducial frame's corners): `projector`
// pixels and the (distorted) camera pixels `seen` that saw them, one to one; the edge
// margin and RANSAC as above. kInvalidInput for lists of different lengths or a
// non-finite point.
Result<CollineationNodes> collineationOfPoints(const Points2& projector, const Points2& seen,
                                               const geom::CameraModel& camera,
                                               const std::string& name,
                                               const PlaneHomographyOptions& options = {});

// The convex hull of `points` (projector pixels) over the w x h frame: how much of a
// projector's image its nodes span.
double coverageOf(const Points2& points, int w, int h);

// The plane's upright basis seen from `camera` (geom::uprightBasis), its origin where
// the camera saw `seen` (ideal pixels) on average, and the collineation from the
// camera's ideal pixels to it (A_wc^-1 of [Raskar02] §4.2.4). kDegenerate when a ray
// through `seen` meets the plane behind the camera (named `name` in the message), the
// camera lies on the plane or the plane is horizontal. `plane` has a unit normal.
Result<geom::PlaneHomography> planeFromCamera(const geom::CameraModel& camera,
                                              const geom::Plane& plane, const Points2& seen,
                                              const std::string& name);

// kInvalidInput for a decoded map whose size is not its camera's, a non-finite or
// zero-normal plane; kTooFewPoints below min_points inliers; kDegenerate when the
// camera lies on the plane, sees the lit points behind it (the plane given is not
// the one lit), the nodes cover less than min_coverage of the projector, or the
// plane is horizontal; the errors of geom::fitHomography (kIllConditioned...).
Result<PlaneHomographyResult> solvePlaneHomographyRoute(const sl::PatternSet& set,
                                                        const DecodedView& view,
                                                        const geom::Plane& plane,
                                                        const PlaneHomographyOptions& options = {});

// The route's solve from nodes already found (collineationNodes, collineationOfPoints)
// by `camera` (named `name`) of a `width` x `height` projector; its errors as above.
Result<PlaneHomographyResult> solvePlaneFromNodes(const CollineationNodes& nodes,
                                                  const geom::CameraModel& camera,
                                                  const std::string& name, const geom::Plane& plane,
                                                  int width, int height,
                                                  const PlaneHomographyOptions& options = {});

}  // namespace procam::calib
