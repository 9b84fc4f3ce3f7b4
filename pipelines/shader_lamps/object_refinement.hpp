#pragma once
// A placed model refined by the surface calibration measured ([Raskar02] §4.1.1 route (a):
// each projector's mesh of the scene triangulated by two cameras; eq. 4.2 with detected
// points): the thousands of measured vertices that lie on the object, against the
// model's surface beside each, fix its pose far better than a handful of picked points.
// Point-to-plane ICP (Chen & Medioni 1992): each measured vertex near the model, with a
// normal that agrees with the model's there, pulls the model along the model's normal;
// the small rigid motion that best satisfies them all is solved in closed form (linearised
// rotation, about the correspondences' centroid for conditioning) and the search radius
// narrows from the picked placement's error to the measurement's. Measured vertices of the
// table or wall around the object, and those bridging its edges (a projector's grid does
// not follow a crease), find no model beside them or disagree in normal, and are left out.
#include <span>
#include <vector>

#include "core/error.hpp"
#include "geometry/intersect.hpp"
#include "shader_lamps/object_placement.hpp"

namespace procam::lamps {

struct RefineOptions {
  double max_distance_m = 0.01;     // the first search radius: the start's error
  double final_distance_m = 0.003;  // the last: a few times the measurement's noise
  double max_normal_deg = 30;       // measured and model normals must agree this well
  int iterations = 30;
};

// A direction the measured points do not fix (in the world): a turn about `axis` through
// the point `through`, or a slide along `axis` (`through`: the measured points' centroid).
struct FreeDirection {
  bool turn = false;
  Vec3 axis = Vec3::UnitX();
  Vec3 through = Vec3::Zero();
};

struct ObjectRefinement {
  ObjectPlacement placement;  // world = R · model + t; rms_m/max_m: the last residuals
  long points = 0;            // measured vertices that pulled at the end
  long candidates = 0;        // measured vertices given
  int iterations = 0;
  double moved_m = 0;     // how far the refinement moved the model's centroid
  double turned_deg = 0;  // and turned it
  // Directions the measured surface left free (e.g. only two faces of a box seen by both
  // cameras: the slide along their common edge): kept as the start had them.
  std::vector<FreeDirection> free;
};

// kInvalidInput for options out of range (radii in (0, 0.1] m, the final not above the
// first, an angle in (0, 90) degrees, 1..200 iterations), a start that is not a rotation,
// or meshes with bad indices or non-finite vertices; kTooFewPoints under 50 measured
// vertices on the model; kDegenerate when those coincide. Directions they do not fix are
// reported in `free`.
Result<ObjectRefinement> refinePlacement(std::span<const geom::TriangleMesh> measured,
                                         const geom::TriangleMesh& model,
                                         const ObjectPlacement& start,
                                         const RefineOptions& options = {});

}  // namespace procam::lamps
