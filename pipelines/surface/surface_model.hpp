#pragma once
// Display-surface model from triangulated points ([Raskar02] §4.1.1: a mesh in projector
// image space; §4.2: planar surfaces need only a plane). A RANSAC plane test picks
// the cheaper model: planar -> plane; otherwise a mesh over the projector grid with
// holes where nothing was decoded (single lost nodes and small clusters between decoded
// ones are decoding dropouts and are closed), simplified where the surface is flat (without
// T-junctions: a simplified quad is a fan to every node of its border).
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/plane_fit.hpp"
#include "surface/stereo_points.hpp"

namespace procam::surface {

struct SurfaceOptions {
  double plane_threshold = 0.003;        // RANSAC inlier distance, metres
  double planar_inlier_fraction = 0.97;  // planar when at least this share are inliers
  double mesh_tolerance = 0.001;         // a coarse quad replaces finer ones within this (metres)
  double max_edge = 0.05;                // longer edges between neighbouring nodes: a hole (metres)
  int max_quad_nodes = 16;               // largest simplified quad, in node intervals (power of 2)
};

struct SurfaceMesh {
  Points3 vertices;                    // world frame
  Points2 projector;                   // projector pixel of each vertex
  std::vector<Eigen::Vector3i> faces;  // vertex indices
};

struct SurfaceModel {
  bool planar = false;
  geom::Plane plane;     // best plane (also for non-planar surfaces)
  double plane_rms = 0;  // RMS distance of the inliers
  double inlier_fraction = 0;
  SurfaceMesh mesh;  // empty when planar
};

// kTooFewPoints below 3 points.
Result<SurfaceModel> buildSurface(const SurfacePoints& points, const SurfaceOptions& options = {});

// Projector-space mesh with holes and quadtree simplification (also used directly).
SurfaceMesh meshInProjectorSpace(const SurfacePoints& points, const SurfaceOptions& options);

// ASCII PLY: vertices (x y z, projector u v) and triangles.
std::string toPly(const SurfaceMesh& mesh);

}  // namespace procam::surface
