#pragma once
// Projectors on one plane registered through camera views that each see only some of
// them ([Raskar02] §4.2.4: on a plane every pair of images is related by a collineation,
// and collineations chain). A view v sees projector p through the collineation H_vp
// (projector pixels -> view pixels); a projector seen by the reference view maps into it
// directly, any other through the views and projectors between them: the homography
// tree of [Chen02]. A chain accumulates the
// error of every link, so the tree is only the start: one least-squares refinement over
// every observation (each view's sightings of each projector) moves all collineations
// at once, and the error of a projector far down the chain stays that of its
// neighbours.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"

namespace procam::geom {

// What one view saw of one projector: projector pixels and where the view saw them
// (ideal, undistorted pixels), one to one.
struct ViewProjectorMatches {
  std::size_t view = 0, projector = 0;
  std::vector<Vec2> projector_px, view_px;
};

struct HomographyTreeOptions {
  std::size_t reference_view = 0;
  // A view and a projector with fewer matches are not linked: their collineation would
  // rest on too few points to carry the chain (and below 4 it is undetermined).
  std::size_t min_matches = 16;
  // Points per view/projector pair in the refinement: spread over the pair's matches,
  // each placed where the pair's own collineation puts it and weighted for the matches
  // it stands for, so every match counts (the residuals reported cover them all). The
  // spread approximates the pair's own weighting of its frame; 200 points keep the
  // normal equations of a 16-projector wall under a second.
  std::size_t refine_matches = 200;
  int max_iterations = 50;
  bool refine = true;  // false: the tree's chained collineations only
  // Names for messages (empty, or one per view / projector): "view 3" otherwise.
  std::vector<std::string> view_names = {}, projector_names = {};
};

struct HomographyTree {
  std::vector<Mat3> projector_to_reference;  // per projector; ||H||_F = 1, H(2,2) >= 0
  std::vector<Mat3> view_to_reference;       // per view; identity for the reference view
  // Views on the tree's chain from the reference view to each projector (1: seen by
  // the reference view itself).
  std::vector<int> chain_views;
  // Residuals over every match, in view pixels: of the chained collineations alone,
  // and after the refinement (equal to them when refine is off).
  double chain_rms_px = 0, chain_max_px = 0;
  double rms_px = 0, max_px = 0;
  std::size_t links = 0, matches = 0;  // view/projector pairs used, their matches
  int iterations = 0;
  bool converged = true;
};

// `matches`: any number of entries per view/projector pair (joined); views and
// projectors count the indices. kInvalidInput for an index out of range, lists of
// different lengths, non-finite coordinates or a reference view out of range;
// kDegenerate when a projector is linked (through views and projectors) to no view the
// reference view is linked to, naming it; the errors of geom::fitHomography for a
// link's own collineation (kDegenerate, kIllConditioned). Views with no link are left
// out (identity, no residuals).
Result<HomographyTree> solveHomographyTree(std::span<const ViewProjectorMatches> matches,
                                           std::size_t views, std::size_t projectors,
                                           const HomographyTreeOptions& options = {});

}  // namespace procam::geom
