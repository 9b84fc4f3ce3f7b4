#pragma once
// Projector calibration: a projector is the dual of a camera ([Raskar02] §3.1.2), P = K[R|t].
// Three routes, all returning K, R, t and the reprojection RMS:
//  (a) 3D surface points triangulated by a calibrated camera pair + the projector
//      pixels that lit them -> 3x4 DLT + LM -> RQ decomposition ([Raskar02] §4.1.1);
//  (b) one calibrated camera and a blank plane at >= 2 orientations ([Raskar02] §7.3),
//      for a projector with square pixels, zero skew and a known c_x (see below);
//  (c) >= 6 fiducials with known 3D positions + the projector pixels lighting them
//      ([Raskar02] §5.2.5).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "surface/stereo_points.hpp"

namespace procam::calib {

struct ProjectorCalibration {
  geom::Intrinsics K;
  geom::Pose pose;    // world -> projector
  double rms_px = 0;  // reprojection RMS in projector pixels
  int points = 0;
  bool scale_known = true;  // route (b) without a known distance: t is up to scale
  // Route (a): per input point, whether it was kept (1) or rejected as inconsistent
  // with the fitted projector (0).
  std::vector<std::uint8_t> inliers;
};

// Route (a). Points whose reprojection error is far above the fit's (a biased
// triangulation, e.g. where a neighbourhood straddles a surface crease) are dropped
// and the matrix refitted. kCoplanar when the surface is (nearly) a plane: the
// message says to add a non-planar object to the scene or to use route (b).
Result<ProjectorCalibration> calibrateProjectorFromSurface(const surface::SurfacePoints& points);

// Route (c). kTooFewPoints below 6 fiducials, kCoplanar for coplanar fiducials.
Result<ProjectorCalibration> calibrateProjectorFromFiducials(std::span<const Vec3> world,
                                                             std::span<const Vec2> projector);

// Route (b): one plane orientation's correspondences, camera pixel (as captured,
// with distortion) <-> projector pixel.
struct PlaneView {
  Points2 camera;
  Points2 projector;
};

// A blank plane seen by one camera leaves a 3-parameter family of projector
// intrinsics (K R + K t w^T for any w gives the same plane homographies), so route
// (b) fixes zero skew, f_x = f_y and c_x; it estimates f, c_y, R, t.
struct PlaneRouteOptions {
  int projector_width = 0, projector_height = 0;  // 0: from the largest projector pixel seen
  std::optional<double> principal_x;              // c_x; default the image centre (width - 1) / 2
  // Distance from the camera centre to the first plane, metres. A blank plane fixes
  // everything but the overall scale; without this, t has unit length.
  std::optional<double> first_plane_distance;
  int max_points_per_plane = 3000;  // evenly subsampled for the final refinement
  double min_plane_angle_deg = 5;   // planes closer in orientation -> kDegenerate
};

Result<ProjectorCalibration> calibrateProjectorFromPlanes(const geom::CameraModel& camera,
                                                          std::span<const PlaneView> views,
                                                          const PlaneRouteOptions& options = {});

}  // namespace procam::calib
