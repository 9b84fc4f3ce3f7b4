#pragma once
// Route (a) from decoded structured light ([Raskar02] §4.1.1): two calibrated cameras
// decode the same pattern set; each decoded map is inverted on a projector grid,
// the nodes both cameras see are triangulated, the projector's 3x4 matrix is fitted
// to them and the display surface is modelled from the points consistent with it.
// Shared by procam-calibrate (files) and procamd (live captures).
#include <string>

#include "calibration/projector_calibration.hpp"
#include "geometry/camera_model.hpp"
#include "geometry/plane_fit.hpp"
#include "structured_light/decoder.hpp"
#include "structured_light/pattern_set.hpp"
#include "surface/stereo_points.hpp"
#include "surface/surface_model.hpp"

namespace procam::calib {

struct DecodedView {
  std::string name;  // names the camera in error messages
  geom::CameraModel camera;
  sl::Decoded decoded;
};

struct StereoRouteResult {
  ProjectorCalibration projector;
  surface::SurfaceModel surface;
  std::size_t triangulated = 0;  // projector nodes seen by both cameras
  std::size_t consistent = 0;    // of those, kept by the projector fit
};

// Inverse-map neighbourhood for a pattern set: Gray-only correspondences are cell
// centres, so it spans several cells; phase-shifted ones are continuous.
double sampleRadius(const sl::PatternSet& set);

// The projector grid nodes (every `step` projector pixels) both cameras decoded,
// triangulated. kInvalidInput when a decoded map's size is not its camera's;
// kTooFewPoints below 20 nodes.
Result<surface::SurfacePoints> triangulateNodes(const sl::PatternSet& set, const DecodedView& a,
                                                const DecodedView& b, int step);

// A calibrated projector as the second view (a projector is a camera in reverse,
// [Raskar02] §4.1.1): the projector grid nodes one camera decoded, triangulated from the
// camera's ray and the projector's ray through the node. `projector` must have its pose,
// intrinsics and distortion. Errors as triangulateNodes.
Result<surface::SurfacePoints> triangulateWithProjector(const sl::PatternSet& set,
                                                        const geom::CameraModel& projector,
                                                        const DecodedView& view, int step);

// A planar scene (solveStereoRoute's kCoplanar): the plane the two cameras
// triangulate, for the plane route (solvePlaneHomographyRoute): RANSAC with five
// times the nodes' own noise (from second differences along the projector grid, at
// least 0.5 mm) as the threshold; kDegenerate when fewer than 90 % of the nodes lie
// on it (not one plane after all). solveStereoRoute answers kCoplanar by the same rule.
// `prior` (the plane other projectors of the wall were calibrated on) is returned,
// with the nodes' residuals, when 90 % of them lie within the threshold of it: every
// projector of one wall then maps onto the same plane.
Result<geom::PlaneFit> triangulatedPlane(const surface::SurfacePoints& nodes,
                                         const std::optional<geom::Plane>& prior = {});

// `step`: projector pixels between grid nodes. kInvalidInput when a decoded map's
// size is not its camera's; kTooFewPoints below 20 triangulated nodes; the errors of
// calibrateProjectorFromSurface (kCoplanar for a planar scene) and buildSurface.
Result<StereoRouteResult> solveStereoRoute(const sl::PatternSet& set, const DecodedView& a,
                                           const DecodedView& b, int step);
// The same from nodes triangulateNodes gave (kCoplanar as above).
Result<StereoRouteResult> solveStereoRoute(const surface::SurfacePoints& nodes);

}  // namespace procam::calib
