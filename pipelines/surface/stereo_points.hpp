#pragma once
// Display-surface points from a calibrated camera pair ([Raskar02] §4.1.1 "Display Surface
// Estimation"): the projector node seen by both cameras is triangulated from their
// two rays. Each point keeps the projector pixel that lit it, which is what
// projector calibration (route a) and the projector-space mesh need.
#include <cstdint>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/camera_model.hpp"
#include "surface/projector_samples.hpp"

namespace procam::surface {

struct SurfacePoints {
  int step = 0, nodes_x = 0, nodes_y = 0;
  std::vector<std::int32_t> index;  // per projector node: point index or -1
  Points3 world;                    // triangulated, world frame of the cameras
  Points2 projector;                // projector pixel of each point
  std::vector<double> gap;          // closest-approach distance of the two rays
};

struct TriangulateOptions {
  double max_gap = 0.005;  // rays passing further apart than this (metres) are dropped
};

// Both sample sets must come from the same projector grid. kTooFewPoints when no
// node is seen by both cameras; kInvalidInput when the grids differ.
Result<SurfacePoints> triangulateStereo(const geom::CameraModel& a, const ProjectorSamples& sa,
                                        const geom::CameraModel& b, const ProjectorSamples& sb,
                                        const TriangulateOptions& options = {});

// The points whose keep[i] is non-zero (e.g. a projector calibration's inliers).
SurfacePoints keepPoints(const SurfacePoints& points, const std::vector<std::uint8_t>& keep);

}  // namespace procam::surface
