#pragma once
// Intensity weights of several projectors lighting one object ([Raskar02] §5.2.5).
// A projector lights a surface point when the point is the first thing its pixel's ray
// meets and it faces the projector at θ_P no larger than a grazing cut-off (60° by
// default: beyond it 1/cos θ exceeds 2, the projector's pixels smear along the surface
// and any calibration error slides the image furthest). Each projector's pixel gets its
// distance, in its own framebuffer, to the nearest pixel that does not light the object:
// the frame's edge, the object's silhouette, the grazing cut-off and the depth
// discontinuities of its depth buffer (where a nearer part of the object hides a farther
// one), so weights fall to zero where its light would end abruptly. A surface point's
// weights are those distances (squared, scaled by how squarely the projector faces the
// point, smoothed: lamp_weights.cpp says why) over their sum across every projector that
// lights it (eq. 4.3), so they sum to one, change smoothly across overlaps, the projector
// that sees a point best gives most of its light, and a region only one projector lights
// gets weight 1 from it.
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "shader_lamps/lamp_view.hpp"
#include "shader_lamps/object_model.hpp"

namespace procam::lamps {

struct LampWeightOptions {
  double max_incidence_deg = 60;  // grazing cut-off θ_P
  // A step in depth between neighbouring pixels steeper than a surface at this angle is
  // a depth discontinuity.
  double discontinuity_deg = 85;
  // Pixels of a projector's own frame kept dark next to its silhouette and on either side
  // of a depth discontinuity: its pixels spread over about one pixel (their footprint and
  // the lens blur), so the last pixel whose centre meets the object would put light past
  // the edge, or onto the part behind it.
  int silhouette_margin_px = 1;
  // How far the object's model may stand from the object (its placement's largest
  // residual, or the calibration's): the margin grows by as many pixels as that is at the
  // object's nearest point to the projector, so no light misses the object.
  double position_error_m = 0;
  // Gaussian sigma, in pixels, smoothing each projector's feathering strength.
  double smoothing_px = 1.5;
};

// One projector of the set: its model (K, lens, pose from the rig) and its view of the
// object; `enabled` false for a projector switched off (it lights nothing, and the
// others take over what they can).
struct Lamp {
  const geom::CameraModel* model = nullptr;
  const LampView* view = nullptr;
  bool enabled = true;
};

struct LampWeights {
  std::vector<cv::Mat> weight;  // per projector, CV_32FC1 in [0, 1]; 0 where it lights nothing
  // Per projector, switched off or not, CV_32FC1: each pixel's distance to the nearest
  // pixel that does not light the object (frame edge, silhouette and its margin, grazing
  // cut-off, depth discontinuity); > 0 where it lights the object.
  std::vector<cv::Mat> reach;
};

// kInvalidInput for no projectors, a missing model or view, a view whose size is not its
// model's, or options out of range (cut-off in (0, 90), discontinuity in (cut-off, 90),
// margin and smoothing in [0, 16], a position error outside [0, 0.1] m).
Result<LampWeights> lampWeights(std::span<const Lamp> lamps, const LampWeightOptions& options = {});

// A weight or reach image (CV_32FC1) read between pixels, as a projector's light reaches
// a point between its pixel centres (clamped to the frame's edge pixels).
float sampleBilinear(const cv::Mat& m, const Vec2& pixel);

// Which projectors see a world point on the side its unit normal faces (the point is the
// first thing their ray meets there): its framebuffer position in each, or nullopt. Their
// weights, read there between pixels, are the share of the point's light each gives.
std::vector<std::optional<Vec2>> lampsSeeing(std::span<const Lamp> lamps, const Vec3& point,
                                             const Vec3& normal);

// How the object's surface is covered, on the side its faces' winding makes the outside,
// from sample points on every face (the centroids of its subdivision into triangles about
// `spacing_m` across, at most 16 per edge): area in m².
struct Coverage {
  double lit_m2 = 0;        // lit by an enabled projector
  double unlit_m2 = 0;      // lit only by projectors switched off: a hole the rig reports
  double never_lit_m2 = 0;  // no projector of the rig reaches it (shadowed, grazing, outside)
  std::vector<std::uint32_t> unlit_faces;  // faces with a sample only switched-off ones light
};

// Empty (all zero) when `weights` are not those of `lamps` (another count).
Coverage lampCoverage(std::span<const Lamp> lamps, const LampWeights& weights,
                      const ObjectModel& object, double spacing_m = 0.002);

}  // namespace procam::lamps
