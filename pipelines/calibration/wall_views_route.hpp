#pragma once
// Route (b′) with cameras at several positions: projectors on a planar wall, each seen by
// some of the cameras, one camera calibrated (intrinsics and pose) and the plane given
// ([Raskar02] §4.2.4). Every other camera needs only its intrinsics, for its lens
// distortion: it is registered to the calibrated one through the projectors both see
// (the homography tree of [Chen02], geom::solveHomographyTree, with its global
// least-squares refinement), so a wall larger than any one camera's view is calibrated
// in one frame without error accumulating along the chain of cameras.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calibration/plane_homography_route.hpp"
#include "core/error.hpp"
#include "geometry/homography_tree.hpp"
#include "geometry/plane_fit.hpp"
#include "geometry/plane_homography.hpp"

namespace procam::calib {

// What camera `camera` saw of projector `projector`'s scan (collineationNodes): a caller
// that scans projector by projector keeps these, not the decoded maps.
struct WallNodes {
  std::size_t projector = 0, camera = 0;
  CollineationNodes nodes;
};

// What one camera at one position saw of one projector's scan: its nodes, or none (and
// why) when it saw too little of that projector to count — no failure for a camera that
// sees only part of the wall. kInvalidInput (bad input) passes through.
struct WallSighting {
  std::optional<CollineationNodes> nodes;
  std::string why;  // when there are none
};
Result<WallSighting> wallSighting(const sl::PatternSet& set, const DecodedView& view,
                                  const PlaneHomographyOptions& options = {});

struct WallViewsOptions {
  PlaneHomographyOptions nodes;      // node step, RANSAC threshold, min_points per sighting
  std::size_t reference_camera = 0;  // the calibrated one
  // For messages (empty, or one per camera / projector): "projector 2" otherwise.
  std::vector<std::string> camera_names = {}, projector_names = {};
};

struct WallViewsResult {
  // Per projector, all in one basis of the plane (upright, seen from the reference camera).
  std::vector<geom::PlaneHomography> projector_to_plane;
  struct Projector {
    std::size_t nodes = 0;        // matched nodes over every camera that saw it
    std::size_t samples = 0;      // nodes seen before RANSAC
    double rms_px = 0;            // their residuals, camera pixels
    double rms_projector_px = 0;  // the same transferred into the projector
    double coverage = 0;          // their convex hull over the projector frame
    std::size_t cameras = 0;      // cameras that saw it (with at least min_points nodes)
  };
  std::vector<Projector> projectors;
  geom::HomographyTree tree;
};

// The solve from nodes. `projector_sizes[p]`: projector p's framebuffer (width, height);
// `reference`: the calibrated camera (named `reference_name` in messages). kInvalidInput
// for an index out of range or a plane without a normal; kDegenerate for a projector
// whose nodes over all cameras cover less than options.nodes.min_coverage of its frame;
// the errors of geom::solveHomographyTree (kDegenerate naming a projector no chain
// reaches) and of planeFromCamera for the reference camera.
Result<WallViewsResult> solveWallViews(std::span<const std::pair<int, int>> projector_sizes,
                                       std::size_t cameras, std::span<const WallNodes> nodes,
                                       const geom::CameraModel& reference,
                                       const std::string& reference_name, const geom::Plane& plane,
                                       const WallViewsOptions& options = {});

}  // namespace procam::calib
