#pragma once
// A given object model (a scan, a CAD file) registered to the rig ([Raskar02] eq. 4.2,
// §5.2.5 "Authoring and Alignment"): points picked or detected on the physical object and
// located in the rig's world (triangulated by its cameras, or lit by calibrated
// projectors' cross-hairs) against the same points of the model give the rigid
// transform that places the model; more than the three a rigid transform needs, so
// that the fit's residual tells a mis-picked point or a model of another object.
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "geometry/intersect.hpp"

namespace procam::lamps {

struct ObjectPlacement {
  Mat3 R = Mat3::Identity();  // world = R · model + t
  Vec3 t = Vec3::Zero();
  double rms_m = 0;                 // of the points' residuals after the fit
  double max_m = 0;                 // the largest residual
  std::vector<double> residuals_m;  // per point, in the order given
};

constexpr std::size_t kMinPlacementPoints = 4;

// kTooFewPoints under four pairs; kInvalidInput for unequal counts or non-finite points;
// kDegenerate for points (near) on one line.
Result<ObjectPlacement> placeObject(std::span<const Vec3> model_points,
                                    std::span<const Vec3> world_points);

// The model's vertices moved into the world.
geom::TriangleMesh placedMesh(const geom::TriangleMesh& model, const ObjectPlacement& placement);

// The model as an ASCII PLY file (vertices x y z in the model's frame, texture coordinates
// as s t when it has them, triangles): the form a placed model is kept in beside rig.json.
std::string modelPly(const geom::TriangleMesh& model);

}  // namespace procam::lamps
